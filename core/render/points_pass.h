// Points mode: every particle a lit sphere impostor coloured by its speed, for diagnosis.
#pragma once

#include "fluidcast/gpu/context.h"
#include "fluidcast/gpu/handle.h"
#include "frame_params.h"

namespace fluidcast::render {

class PointsPass {
 public:
  PointsPass(gpu::Context& context, VkRenderPass render_pass);
  // Inside the render pass: draws `count` particles.
  void record(VkCommandBuffer commands, const DrawConstants& draw, std::uint32_t count) const;

 private:
  gpu::UniquePipelineLayout layout_;
  gpu::UniquePipeline pipeline_;
};

}  // namespace fluidcast::render

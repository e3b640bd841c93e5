// Renders frames offscreen and reads them back: the particles are read where they are (the GPU
// solver's buffers, or a ParticleUpload of a CPU solver's), nothing else crosses to the GPU.
// Today the points mode exists; SSFR and Marching Cubes are the next passes (issue 4).
#pragma once

#include <glm/glm.hpp>

#include "fluidcast/codec/image.h"
#include "fluidcast/gpu/buffer.h"
#include "fluidcast/gpu/command_slot.h"
#include "fluidcast/render/camera.h"
#include "fluidcast/render/render_target.h"

namespace fluidcast::render {

class PointsPass;

// Where the particles are on the GPU: vec4 positions and velocities (w unused).
struct ParticleView {
  VkDeviceAddress position = 0;
  VkDeviceAddress velocity = 0;
  std::uint32_t count = 0;
  float radius = 0.01f;  // m
};

struct PointsStyle {
  glm::vec3 slow_colour{0.10f, 0.35f, 0.85f};
  glm::vec3 fast_colour{0.90f, 0.95f, 1.00f};
  float full_speed = 2.0f;  // m/s that get fast_colour
};

class FrameRenderer {
 public:
  // Throws std::invalid_argument for a size of zero or beyond the device's limits.
  FrameRenderer(gpu::Context& context, std::uint32_t width, std::uint32_t height);
  ~FrameRenderer();

  glm::vec4 background{0.06f, 0.07f, 0.09f, 1.0f};
  PointsStyle points;

  // Draws one frame and returns it (waits for it). Throws std::invalid_argument for a camera that
  // is not finite or out of range.
  codec::ImageRgba render(const ParticleView& particles, const OrbitCamera& camera);

 private:
  gpu::Context* context_;
  RenderTarget target_;
  std::unique_ptr<PointsPass> points_pass_;
  gpu::Buffer frame_params_;
  gpu::Buffer readback_;
  gpu::CommandSlot commands_;
};

}  // namespace fluidcast::render

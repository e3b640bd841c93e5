// One compute shader, ready to dispatch: the pipeline and its layout. Shaders take everything
// through push constants (buffer device addresses and counts), so there are no descriptor sets.
// The workgroup size is specialisation constant 0, set here, so C++ and GLSL cannot disagree;
// `constants` are 32-bit values for constant_id 1, 2, … (sizes a driver can unroll loops by).
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "fluidcast/gpu/context.h"
#include "fluidcast/gpu/handle.h"

namespace fluidcast::gpu {

// One figure the driver gives of a pipeline's compiled code ("Register Count": "40").
struct PipelineStatistic {
  std::string name;
  std::string value;
};

class ComputePipeline {
 public:
  ComputePipeline(Context& context, std::span<const std::uint32_t> spirv,
                  std::uint32_t push_constant_bytes, std::uint32_t group_size,
                  std::span<const std::uint32_t> constants = {});

  std::uint32_t group_size() const { return group_size_; }

  // What the driver says of the compiled code, in its words, where the context captures it
  // (Context::pipeline_statistics_captured); none otherwise.
  std::vector<PipelineStatistic> statistics() const;

  // Binds the pipeline and dispatches enough workgroups for `items` invocations (none for 0).
  // Beyond the device's workgroup-count limit in x the groups spill into y; shaders compute their
  // linear group index as gl_WorkGroupID.x + gl_NumWorkGroups.x * gl_WorkGroupID.y.
  template <class Push>
  void dispatch(VkCommandBuffer commands, const Push& push, std::uint64_t items) const {
    static_assert(sizeof(Push) <= 128, "push constants beyond the guaranteed 128 bytes");
    dispatch_bytes(commands, &push, sizeof(Push), items);
  }
  // Binds the pipeline and dispatches the workgroups a VkDispatchIndirectCommand at `offset` in
  // `arguments` says, as the GPU left them (each count within the device's limits).
  template <class Push>
  void dispatch_indirect(VkCommandBuffer commands, const Push& push, VkBuffer arguments,
                         VkDeviceSize offset) const {
    static_assert(sizeof(Push) <= 128, "push constants beyond the guaranteed 128 bytes");
    check_push(sizeof(Push));
    bind(commands, &push, sizeof(Push));
    vkCmdDispatchIndirect(commands, arguments, offset);
  }

 private:
  void dispatch_bytes(VkCommandBuffer commands, const void* push, std::uint32_t bytes,
                      std::uint64_t items) const;
  void check_push(std::uint32_t bytes) const;  // throws std::logic_error for the wrong size
  void bind(VkCommandBuffer commands, const void* push, std::uint32_t bytes) const;

  VkDevice device_;
  bool captured_;
  UniquePipelineLayout layout_;
  UniquePipeline pipeline_;
  std::uint32_t push_constant_bytes_;
  std::uint32_t group_size_;
  std::uint32_t max_groups_x_;
  std::uint32_t max_groups_y_;
};

}  // namespace fluidcast::gpu

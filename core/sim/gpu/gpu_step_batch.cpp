#include "fluidcast/sim/gpu_step_batch.h"

#include <algorithm>
#include <utility>

#include "fluidcast/gpu/buffer.h"

namespace fluidcast::sim {
namespace {

// A step's passes read and write with shaders and with transfers (parameters, fills, copies of
// figures): each pass waits for both kinds before it.
constexpr VkPipelineStageFlags kPassStages =
    VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT;
constexpr VkAccessFlags kPassWrites = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
constexpr VkAccessFlags kPassAccess = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT |
                                      VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;

void pass_barrier(VkCommandBuffer commands) {
  gpu::memory_barrier(commands, kPassStages, kPassWrites, kPassStages, kPassAccess);
}

// Before a submission's first pass: what earlier submissions wrote, and the frames that read the
// particles with vertex and fragment shaders (write after read).
void submission_barrier(VkCommandBuffer commands) {
  gpu::memory_barrier(
      commands,
      kPassStages | VK_PIPELINE_STAGE_VERTEX_SHADER_BIT | VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT,
      kPassWrites, kPassStages, kPassAccess);
}

}  // namespace

GpuStepBatch::GpuStepBatch(gpu::Context& context)
    : context_(&context), slots_{Slot(context), Slot(context), Slot(context), Slot(context)} {}

void GpuStepBatch::queue(const void* owner, std::uint64_t particles, std::vector<Pass> passes,
                         Receipt& receipt) {
  receipt = Receipt{};
  queued_.push_back({owner, particles, std::move(passes), &receipt});
}

bool GpuStepBatch::holds(const void* owner) const {
  return std::any_of(queued_.begin(), queued_.end(),
                     [owner](const Queued& q) { return q.owner == owner; });
}

void GpuStepBatch::forget(const void* owner) {
  std::erase_if(queued_, [owner](const Queued& q) { return q.owner == owner; });
}

void GpuStepBatch::submit() {
  if (queued_.empty()) return;
  // Taken out first: a solver destroyed while this submits (one retired earlier, released by the
  // context) must find nothing of its own left to forget.
  std::vector<Queued> steps = std::exchange(queued_, {});
  try {
    record_and_submit(steps);
  } catch (...) {
    // Nothing was submitted: the steps wait for the next try, and their owners' waits stay
    // meaningful (a step that vanished would count as running for ever).
    queued_.insert(queued_.begin(), std::make_move_iterator(steps.begin()),
                   std::make_move_iterator(steps.end()));
    throw;
  }
}

void GpuStepBatch::record_and_submit(std::vector<Queued>& steps) {
  // One lane per owner: its steps' passes one after another, each pass knowing its step.
  struct Lane {
    std::uint64_t particles = 0;
    std::vector<std::pair<const Pass*, Receipt*>> passes;
  };
  std::vector<Lane> lanes;
  std::vector<const void*> lane_owner;
  for (Queued& step : steps) {
    step.receipt->passes.clear();  // a failed try may have begun them
    const auto found = std::find(lane_owner.begin(), lane_owner.end(), step.owner);
    const std::size_t lane = static_cast<std::size_t>(found - lane_owner.begin());
    if (found == lane_owner.end()) {
      lane_owner.push_back(step.owner);
      lanes.emplace_back();
    }
    lanes[lane].particles = std::max(lanes[lane].particles, step.particles);
    for (const Pass& pass : step.passes) lanes[lane].passes.emplace_back(&pass, step.receipt);
  }
  std::size_t pass_count = 0;
  for (const Lane& lane : lanes) pass_count = std::max(pass_count, lane.passes.size());

  Slot& slot = slots_[next_slot_];
  next_slot_ = (next_slot_ + 1) % kSubmissionsInFlight;
  const VkCommandBuffer commands = slot.commands.begin();
  // Owners still to read the old timestamps keep them; this submission gets its own.
  if (!slot.timestamps || slot.timestamps.use_count() > 1) {
    slot.timestamps = std::make_shared<gpu::TimestampQueries>(*context_, kTimestampCapacity);
  }
  const bool timed = context_->timestamps_supported();
  // A timestamp after every pass while the pool holds them all; past that, after every group of
  // `group` passes, each pass of a group given an equal part of the group's time: the
  // submission's time is still handed out whole, but a step's part of a group, and its split
  // among stages, are then estimates.
  const std::size_t group =
      std::max<std::size_t>((pass_count + kTimestampCapacity - 2) / (kTimestampCapacity - 1), 1);
  slot.timestamps->reset(commands);
  submission_barrier(commands);
  // Each group lies between two consecutive marks: the one before it and the one after.
  std::uint32_t from = timed ? slot.timestamps->mark(commands) : 0;
  for (std::size_t k = 0; k < pass_count; ++k) {
    std::uint64_t weight = 0;
    for (const Lane& lane : lanes) {
      if (k >= lane.passes.size()) continue;
      lane.passes[k].first->record(commands);
      weight += std::max<std::uint64_t>(lane.particles, 1);
    }
    pass_barrier(commands);
    if (!timed) continue;
    const std::size_t group_size = std::min(group, pass_count - k / group * group);
    for (const Lane& lane : lanes) {
      if (k >= lane.passes.size()) continue;
      const auto [pass, receipt] = lane.passes[k];
      const double share = static_cast<double>(std::max<std::uint64_t>(lane.particles, 1)) /
                           double(weight) / double(group_size);
      receipt->passes.push_back({from, from + 1, share, pass->stage, pass->index});
    }
    if ((k + 1) % group == 0 || k + 1 == pass_count) from = slot.timestamps->mark(commands);
  }
  gpu::to_host_barrier(commands);
  const std::uint64_t serial = slot.commands.submit();
  for (Queued& step : steps) {
    step.receipt->serial = serial;
    if (timed) step.receipt->timestamps = slot.timestamps;
  }
}

}  // namespace fluidcast::sim

// Steps of several GPU solvers on one context, recorded into one submission with their passes
// interleaved: pass k of every queued step, then one barrier, then pass k + 1. Small fluids are
// bound by launch latency and barriers, not by arithmetic, so 32 of them stepped this way cost
// little more than one (docs/frame-loop.md). The solvers' buffers are disjoint, so a pass of one
// never waits for another's data, only for the shared barrier.
//
// A solver made without a batch keeps one of its own and submits each step as it is queued. A
// solver given a shared batch queues its steps there until the batch's owner calls submit() (a
// frame loop: after every session has queued its steps, before anything draws them), or until the
// solver needs them done (snapshot, synchronize, a change of particles, or a fifth step while its
// ring of four is still waiting), which submits the whole batch.
// Retire a solver only while it has no step waiting in a shared batch (submit first): a step
// recorded after its solver was retired would outlive it. A solver that goes away with steps
// still waiting takes them with it (its destructor forgets them).
#pragma once

#include <vulkan/vulkan.h>

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "fluidcast/gpu/command_slot.h"

namespace fluidcast::sim {

class GpuStepBatch {
 public:
  // One pass of a step: commands that may start once everything recorded before them is done.
  // `stage` and `index` name it for the step's owner, which sorts the GPU time it is given.
  struct Pass {
    int stage = 0;
    int index = 0;
    std::function<void(VkCommandBuffer)> record;
  };
  // What a step's owner learns when the step is submitted: the submission's serial, and the GPU
  // time of each of its passes as a share of the pass it ran in, split by particles among the
  // steps in that pass (read the timestamps once the serial has finished). In a submission of
  // more passes than kTimestampCapacity, `from` and `to` bound a group of passes, and `share`
  // is this step's part of the pass over the passes in the group.
  struct Receipt {
    struct Timed {
      std::uint32_t from, to;  // timestamps around the shared pass (or group of passes)
      double share;            // of that time, this pass's part for this step
      int stage, index;
    };
    std::uint64_t serial = 0;                           // 0: waiting in the batch
    std::shared_ptr<gpu::TimestampQueries> timestamps;  // null when the submission was untimed
    std::vector<Timed> passes;
  };

  explicit GpuStepBatch(gpu::Context& context);
  GpuStepBatch(const GpuStepBatch&) = delete;
  GpuStepBatch& operator=(const GpuStepBatch&) = delete;

  // Timestamps a submission may write: one after each pass up to 8191 passes (one PBF step at the
  // default max_substeps, 256 substeps of 13 to 15 passes at 4 iterations, a step's last two
  // more, fits), one after each group of passes beyond. 64 KiB of queries a slot.
  static constexpr std::uint32_t kTimestampCapacity = 8192;

  // Queues a step of `owner` (after its steps queued before), weighing `particles` in the split
  // of GPU time. `receipt` must stay valid until it is filled or forget(owner) is called.
  void queue(const void* owner, std::uint64_t particles, std::vector<Pass> passes,
             Receipt& receipt);
  bool holds(const void* owner) const;
  // Drops the owner's waiting steps (an owner that goes away).
  void forget(const void* owner);
  // Records every waiting step into one command buffer and submits it; nothing when none waits.
  void submit();

 private:
  struct Queued {
    const void* owner;
    std::uint64_t particles;
    std::vector<Pass> passes;
    Receipt* receipt;
  };
  // Throws what recording or submitting threw, having submitted nothing.
  void record_and_submit(std::vector<Queued>& steps);

  struct Slot {
    explicit Slot(gpu::Context& context) : commands(context) {}
    std::shared_ptr<gpu::TimestampQueries> timestamps;
    // Last, so that it is destroyed first: its destructor waits for the submission that writes
    // the timestamps.
    gpu::CommandSlot commands;
  };
  static constexpr std::size_t kSubmissionsInFlight = 4;

  gpu::Context* context_;
  std::vector<Queued> queued_;
  std::array<Slot, kSubmissionsInFlight> slots_;
  std::size_t next_slot_ = 0;
};

}  // namespace fluidcast::sim

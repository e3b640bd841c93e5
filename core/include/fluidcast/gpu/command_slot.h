// A command buffer that is recorded, submitted, and recorded again once its fence says the GPU is
// done with it. A ring of these keeps the host recording one step while the GPU runs another.
// Its destructor waits for its last submission: an owner replaced while its work is in flight is
// retired to the context (Context::retire) rather than destroyed, so that wait is not a drain.
#pragma once

#include "fluidcast/gpu/context.h"
#include "fluidcast/gpu/handle.h"

namespace fluidcast::gpu {

class CommandSlot {
 public:
  explicit CommandSlot(Context& context);
  ~CommandSlot();
  CommandSlot(CommandSlot&& other) noexcept;
  CommandSlot& operator=(CommandSlot&&) = delete;

  // Waits for the last submission of this slot, then starts recording afresh.
  VkCommandBuffer begin();
  std::uint64_t submit();  // returns the submission's serial (Context::submit)
  void wait() const;
  bool busy() const;  // submitted and not yet finished

 private:
  Context* context_;
  UniqueCommandPool pool_;
  VkCommandBuffer commands_ = VK_NULL_HANDLE;
  UniqueFence fence_;
  bool submitted_ = false;
};

// Ticks from timestamp `from` to `to` of a counter with `valid_bits` bits (timestampValidBits):
// one narrower than 64 bits wraps, and the difference is taken modulo its range; a `to` before
// `from` (more than half the range apart) measures 0.
std::uint64_t timestamp_ticks_between(std::uint64_t from, std::uint64_t to,
                                      std::uint32_t valid_bits);

// GPU timestamps written between stages of a command buffer, read once its fence has signalled.
class TimestampQueries {
 public:
  TimestampQueries(Context& context, std::uint32_t capacity);

  // Resets the pool; recorded before the first mark() of a submission.
  void reset(VkCommandBuffer commands);
  // Writes the next timestamp when all earlier commands are done; returns its index.
  std::uint32_t mark(VkCommandBuffer commands);
  std::uint32_t marks() const { return used_; }
  // Milliseconds between marks `from` and `to` of the finished submission; 0 without timestamps.
  double elapsed_ms(std::uint32_t from, std::uint32_t to);
  // Fetches the finished submission's timestamps, after its fence; once (several readers of one
  // submission may each call it).
  void fetch();

 private:
  Context* context_;
  UniqueQueryPool pool_;
  std::uint32_t capacity_;
  std::uint32_t used_ = 0;
  bool fetched_ = false;
  std::vector<std::uint64_t> ticks_;
};

}  // namespace fluidcast::gpu

#include "fluid_stream.h"

#include <algorithm>
#include <utility>

namespace fluidcast::client {
namespace {

// Inputs awaiting a frame, and latencies kept: the newest.
constexpr std::size_t kKeptInputs = 1024;
constexpr std::size_t kKeptLatencies = 100000;

}  // namespace

void SessionChanges::arrived(v1::SessionState state) {
  std::lock_guard lock(mutex_);
  newest_ = std::move(state);
}

void SessionChanges::apply_to(v1::Welcome& welcome) {
  std::lock_guard lock(mutex_);
  if (newest_) *welcome.mutable_state() = *std::exchange(newest_, std::nullopt);
}

double percentile(std::vector<double> values, double p) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  return values[std::min(values.size() - 1, std::size_t(p * double(values.size())))];
}

std::uint64_t LatencyTracker::sent() {
  std::uint64_t id = 0;
  {
    std::lock_guard lock(mutex_);
    id = next_++;
  }
  sent(id);
  return id;
}

void LatencyTracker::sent(std::uint64_t id, std::chrono::steady_clock::time_point at) {
  std::lock_guard lock(mutex_);
  unanswered_[id] = at;
  if (unanswered_.size() > kKeptInputs) unanswered_.erase(unanswered_.begin());
}

void LatencyTracker::forget_unanswered() {
  std::lock_guard lock(mutex_);
  unanswered_.clear();
}

void LatencyTracker::frame_reflects(std::uint64_t newest_event) {
  const auto now = std::chrono::steady_clock::now();
  std::lock_guard lock(mutex_);
  for (auto it = unanswered_.begin(); it != unanswered_.end() && it->first <= newest_event;) {
    latencies_ms_.push_back(std::chrono::duration<double, std::milli>(now - it->second).count());
    it = unanswered_.erase(it);
  }
  if (latencies_ms_.size() > kKeptLatencies) {
    latencies_ms_.erase(latencies_ms_.begin(), latencies_ms_.begin() + kKeptLatencies / 2);
  }
}

std::vector<double> LatencyTracker::latencies_ms() const {
  std::lock_guard lock(mutex_);
  return latencies_ms_;
}

void FrameQueue::push(v1::Frame frame) {
  std::lock_guard lock(mutex_);
  frames_.push_back(std::move(frame));
  while (frames_.size() > keep_) frames_.pop_front();
  changed_.notify_all();
}

void FrameQueue::close() {
  std::lock_guard lock(mutex_);
  closed_ = true;
  changed_.notify_all();
}

std::optional<v1::Frame> FrameQueue::pop(std::chrono::milliseconds timeout) {
  std::unique_lock lock(mutex_);
  changed_.wait_for(lock, timeout, [this] { return !frames_.empty() || closed_; });
  if (frames_.empty()) return std::nullopt;
  v1::Frame frame = std::move(frames_.front());
  frames_.pop_front();
  return frame;
}

bool FrameQueue::wait_closed(std::chrono::milliseconds timeout) {
  std::unique_lock lock(mutex_);
  return changed_.wait_for(lock, timeout, [this] { return closed_; });
}

bool FrameQueue::closed() const {
  std::lock_guard lock(mutex_);
  return closed_;
}

std::uint64_t FluidStream::pointer(std::uint32_t id, v1::PointerEvent::Phase phase, float x,
                                   float y) {
  v1::ClientMessage message;
  v1::PointerEvent& event = *message.mutable_pointer();
  event.set_pointer_id(id);
  event.set_phase(phase);
  event.set_x(x);
  event.set_y(y);
  return send(std::move(message));
}

std::uint64_t FluidStream::tilt(float x, float y, float z) {
  v1::ClientMessage message;
  message.mutable_tilt()->set_x(x);
  message.mutable_tilt()->set_y(y);
  message.mutable_tilt()->set_z(z);
  return send(std::move(message));
}

std::uint64_t FluidStream::command(const v1::Command& command) {
  v1::ClientMessage message;
  *message.mutable_command() = command;
  return send(std::move(message));
}

}  // namespace fluidcast::client

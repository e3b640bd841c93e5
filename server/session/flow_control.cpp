#include "flow_control.h"

#include <algorithm>

namespace fluidcast::server {

void FlowControl::ask(std::uint32_t fps, std::uint32_t jpeg_quality, bool adaptive) {
  requested_quality_ = jpeg_quality_ =
      jpeg_quality == 0 ? kDefaultQuality : static_cast<int>(jpeg_quality);
  adaptive_ = adaptive;
  frame_interval_ =
      std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(1.0 / fps));
  next_frame_ = {};  // a new rate starts now, not after the old interval
  render_size_ = asked_size_;
}

void FlowControl::ask_size(Size size) { asked_size_ = render_size_ = size; }

bool FlowControl::due(Clock::time_point now) const {
  return throttled() ? overdue(now) >= kThrottledFrameEvery : now >= next_frame_;
}

bool FlowControl::skips_frame(Clock::time_point now) {
  const Clock::time_point due = std::max(next_frame_, next_skipped_);
  if (!throttled() || now < due) return false;
  next_skipped_ = due + frame_interval_;
  return true;
}

void FlowControl::rendered(Clock::time_point now) {
  next_frame_ = std::max(next_frame_ + frame_interval_, now);
  last_rendered_ = now;
}

std::uint64_t FlowControl::produced(Clock::time_point now) {
  ++sequence_;
  produced_at_[sequence_ % produced_at_.size()] = now;
  return sequence_;
}

void FlowControl::acknowledge(std::uint64_t sequence, Clock::time_point now) {
  if (sequence == 0 || sequence > sequence_ || sequence <= acknowledged_) return;
  acknowledged_ = sequence;
  if (sequence_ - sequence < produced_at_.size()) {
    const std::chrono::duration<double, std::milli> rtt =
        now - produced_at_[sequence % produced_at_.size()];
    round_trip_ms_ = rtt.count();
  }
  adapt(now);
}

// Lower JPEG quality, then the size, while frames queue up behind the client or the round trip
// is long; raise them again, the size first, when it keeps up.
void FlowControl::adapt(Clock::time_point now) {
  if (!adaptive_ || now - last_adapted_ < kAdaptEvery) return;
  last_adapted_ = now;
  const double round_trip = round_trip_ms_.value_or(0.0);
  const bool behind = round_trip > kBehindMs || throttled();
  const bool keeping_up = round_trip < kKeepingUpMs && !throttled();
  Size& size = render_size_;
  if (behind) {
    if (jpeg_quality_ > kLowestAdaptiveQuality) {
      jpeg_quality_ = std::max(kLowestAdaptiveQuality, jpeg_quality_ - 10);
    } else if (size.height > kSmallestAdaptiveHeight) {
      size = {std::max(1u, size.width * 3 / 4), std::max(1u, size.height * 3 / 4)};
    }
  } else if (keeping_up) {
    if (size.width < asked_size_.width) {
      size = {std::min(asked_size_.width, size.width * 4 / 3 + 1),
              std::min(asked_size_.height, size.height * 4 / 3 + 1)};
    } else if (jpeg_quality_ < requested_quality_) {
      jpeg_quality_ = std::min(requested_quality_, jpeg_quality_ + 5);
    }
  }
}

}  // namespace fluidcast::server

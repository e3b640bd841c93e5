#include "sim_speed.h"

namespace fluidcast::server {

void SimSpeed::record(Clock::time_point now, double sim_time, bool running) {
  if (!running || (!samples_.empty() && sim_time < samples_.back().sim_time)) samples_.clear();
  if (!running) return;
  samples_.push_back({now, sim_time});
  // Keep one sample at or before the window's start, so the window is always covered.
  while (samples_.size() > 2 && now - samples_[1].at >= kWindow) samples_.pop_front();
}

double SimSpeed::speed() const {
  if (samples_.size() < 2) return 0.0;
  const double wall =
      std::chrono::duration<double>(samples_.back().at - samples_.front().at).count();
  return wall > 0.0 ? (samples_.back().sim_time - samples_.front().sim_time) / wall : 0.0;
}

}  // namespace fluidcast::server

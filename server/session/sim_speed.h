// The simulation speed a session runs at: simulated seconds per wall-clock second, over the last
// second or so (1: real time; below 1: slow motion, when the GPU's share cannot keep up).
#pragma once

#include <chrono>
#include <deque>

namespace fluidcast::server {

class SimSpeed {
 public:
  using Clock = std::chrono::steady_clock;
  // The window the speed is averaged over.
  static constexpr Clock::duration kWindow = std::chrono::seconds(1);

  // The simulated clock at a tick. A clock that went back (a reset) or a pause starts the measure
  // afresh.
  void record(Clock::time_point now, double sim_time, bool running);
  // Starts the measure afresh: the clock was set (a loaded snapshot, which may lie ahead).
  void restart() { samples_.clear(); }
  // 0 until two ticks of a running simulation have been recorded.
  double speed() const;

 private:
  struct Sample {
    Clock::time_point at;
    double sim_time;
  };
  std::deque<Sample> samples_;
};

}  // namespace fluidcast::server

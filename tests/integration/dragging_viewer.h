// One viewer that drags a finger to and fro through its fluid (20 moves a second) for `warm_up`
// + `seconds`, and what it measured over the last `seconds` only (by then pipelines are compiled
// and the server's costs measured): the load benchmark's clients and the frame-loop tests.
#pragma once

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>
#include <vector>

#include "stream_client.h"

namespace fluidcast::testing {

struct ViewerRun {
  std::size_t frames = 0;
  std::size_t bytes = 0;
  double seconds = 0.0;  // measured
  std::vector<double> latencies_ms;
  std::vector<double> sim_speed, gpu_ms, sim_ms;  // per frame: speed, render + read-back, steps
  std::string error;     // how the stream ended, when it did not end well
  double fps() const { return seconds > 0.0 ? double(frames) / seconds : 0.0; }
};

inline double percentile(std::vector<double> values, double p) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  return values[std::min(values.size() - 1, std::size_t(p * double(values.size())))];
}

inline ViewerRun run_dragging_viewer(const std::string& address, const v1::Hello& hello,
                                     double warm_up, double seconds) {
  using Clock = std::chrono::steady_clock;
  ViewerRun run;
  run.seconds = seconds;
  try {
    client::StreamClient stream(client::connect(address), hello);
    const auto start = Clock::now();
    double next_move = 0.0;
    bool down = false, measuring = false;
    std::size_t latencies_before = 0;
    while (!stream.ended()) {
      const double t = std::chrono::duration<double>(Clock::now() - start).count();
      if (t >= warm_up + seconds) break;
      if (!measuring && t >= warm_up) {
        measuring = true;
        latencies_before = stream.latencies_ms().size();
      }
      if (t >= next_move) {
        const float x = 0.5f + 0.3f * float(std::sin(t * 3.0));
        stream.pointer(0, down ? v1::PointerEvent::MOVE : v1::PointerEvent::DOWN, x, 0.6f);
        down = true;
        next_move += 0.05;
      }
      if (auto frame = stream.next_frame(std::chrono::milliseconds(5)); frame && measuring) {
        ++run.frames;
        run.bytes += frame->jpeg().size();
        run.sim_speed.push_back(frame->sim_speed());
        run.gpu_ms.push_back(frame->timings().render_ms() + frame->timings().readback_ms());
        run.sim_ms.push_back(frame->timings().sim_ms());
      }
    }
    const grpc::Status status = stream.ended() ? stream.status() : stream.finish();
    if (!status.ok()) run.error = status.error_message();
    const auto latencies = stream.latencies_ms();
    if (latencies.size() >= latencies_before) {
      run.latencies_ms.assign(latencies.begin() + std::ptrdiff_t(latencies_before),
                              latencies.end());
    }
  } catch (const std::exception& e) {
    run.error = e.what();
  }
  return run;
}

}  // namespace fluidcast::testing

// The server's counters and timings, shown in Prometheus text format on GET /metrics.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <functional>
#include <map>
#include <mutex>
#include <string>

namespace fluidcast::server {

// Milliseconds, bucketed: what Prometheus calls a histogram.
class Histogram {
 public:
  static constexpr std::array<double, 12> kBounds = {0.25, 0.5, 1, 2, 4, 8, 16, 32, 64, 128, 256, 512};
  void observe(double milliseconds);
  void write(std::string& out, const std::string& name, const std::string& help) const;

 private:
  mutable std::mutex mutex_;
  std::array<std::uint64_t, kBounds.size() + 1> counts_{};
  double sum_ = 0.0;
};

// One session's figures, exported with its id as a label.
struct SessionFigures {
  double sim_speed = 0.0;   // simulated seconds per wall second
  double substep_ms = 0.0;  // measured cost of one substep (GPU time on a GPU solver)
  double frame_ms = 0.0;    // measured GPU cost of its viewers' frames, summed over viewers
  std::uint64_t particles = 0;
};

struct Metrics {
  std::atomic<std::uint64_t> sessions{0};
  std::atomic<std::uint64_t> viewers{0};
  std::atomic<std::uint64_t> frames_sent{0};
  std::atomic<std::uint64_t> frames_dropped{0};  // replaced before a slow viewer read them
  std::atomic<std::uint64_t> frames_skipped{0};  // not rendered: the viewer had enough in flight
  // Not rendered in a tick: the session had spent its share of the GPU while others were watched.
  std::atomic<std::uint64_t> frames_deferred{0};
  std::atomic<std::uint64_t> bytes_sent{0};
  std::atomic<std::uint64_t> streams_refused{0};
  std::atomic<std::uint64_t> gpu_memory_bytes{0};
  Histogram sim_ms, render_ms, readback_ms, encode_ms, round_trip_ms;
  // Where a frame's time went, in the order it passed (v1::StageTimings says each).
  Histogram input_wait_ms, queue_ms, encode_wait_ms, server_ms;
  Histogram send_ms;  // from a frame's hand-over to the transport until it is written

  void set_session(const std::string& id, const SessionFigures& figures);
  void forget_session(const std::string& id);
  std::string prometheus_text() const;

 private:
  mutable std::mutex sessions_mutex_;
  std::map<std::string, SessionFigures> session_figures_;
};

}  // namespace fluidcast::server

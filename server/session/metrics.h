// The server's counters and timings, shown in Prometheus text format on GET /metrics: base units
// (seconds, bytes), labels where a count splits by transport or reason, and the build's version.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <map>
#include <mutex>
#include <string>

#include "refusal.h"

namespace fluidcast::gpu {
struct DeviceInfo;
}

namespace fluidcast::server {

enum class Transport { grpc, websocket };
constexpr std::array kTransports = {Transport::grpc, Transport::websocket};
const char* transport_name(Transport transport);

// Durations, bucketed (what Prometheus calls a histogram): observed in the milliseconds the
// server's clocks give, exported in seconds.
class Histogram {
 public:
  static constexpr std::array<double, 12> kBoundsSeconds = {
      0.00025, 0.0005, 0.001, 0.002, 0.004, 0.008, 0.016, 0.032, 0.064, 0.128, 0.256, 0.512};
  void observe_ms(double milliseconds);
  // The series of one histogram (`labels` is empty or `key="value",...`), without HELP and TYPE.
  void write_series(std::string& out, const std::string& name, const std::string& labels) const;

 private:
  mutable std::mutex mutex_;
  std::array<std::uint64_t, kBoundsSeconds.size() + 1> counts_{};
  double sum_seconds_ = 0.0;
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
  // Rendered though the session's share was spent: a viewer's frame rate floor.
  std::atomic<std::uint64_t> frames_on_floor{0};
  std::atomic<std::uint64_t> bytes_sent{0};
  std::atomic<std::uint64_t> gpu_memory_bytes{0};
  Histogram sim_time, render_time, readback_time, encode_time, round_trip_time;
  // Where a frame's time went, in the order it passed (v1::StageTimings says each).
  Histogram input_wait_time, queue_time, encode_wait_time, server_time;

  // What the server runs on, for fluidcast_device_info.
  void describe_device(const gpu::DeviceInfo& device);
  // The server ended a stream with an error status: at its Hello, for a message, or with its
  // session (a limit, a failure, the idle timeout, a resume elsewhere, shutdown).
  void refused(Transport transport, RefusalCode reason);
  // From a frame's hand-over to the transport until it was written.
  void sent(Transport transport, double milliseconds);
  void set_session(const std::string& id, const SessionFigures& figures);
  void forget_session(const std::string& id);
  std::string prometheus_text() const;

 private:
  void write_totals(std::string& out) const;
  void write_histograms(std::string& out) const;
  void write_labelled(std::string& out) const;

  mutable std::mutex mutex_;  // guards what follows
  std::string device_labels_;  // fluidcast_device_info's, as describe_device wrote them
  std::map<std::pair<Transport, RefusalCode>, std::uint64_t> refusals_;
  std::map<std::string, SessionFigures> session_figures_;
  std::array<Histogram, kTransports.size()> send_time_;
};

}  // namespace fluidcast::server

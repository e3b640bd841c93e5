#include "metrics.h"

#include <cstdio>

namespace fluidcast::server {
namespace {

std::string number(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.17g", value);
  return text;
}

void write_value(std::string& out, const std::string& name, const char* type,
                 const std::string& help, std::uint64_t value) {
  out += "# HELP " + name + " " + help + "\n# TYPE " + name + " " + type + "\n";
  out += name + " " + std::to_string(value) + "\n";
}

// The per-session gauges, labelled with the session's id.
struct SessionSeries {
  const char* name;
  const char* help;
  double (*value)(const SessionFigures&);
};
constexpr SessionSeries kSessionSeries[] = {
    {"fluidcast_session_sim_speed",
     "Simulated seconds per wall second over the last second (1: real time).",
     [](const SessionFigures& f) { return f.sim_speed; }},
    {"fluidcast_session_substep_milliseconds",
     "Measured cost of one solver substep (GPU time on a GPU solver).",
     [](const SessionFigures& f) { return f.substep_ms; }},
    {"fluidcast_session_frame_milliseconds",
     "Measured GPU time of one frame for each of the session's viewers, summed.",
     [](const SessionFigures& f) { return f.frame_ms; }},
    {"fluidcast_session_particles", "Particles in the session.",
     [](const SessionFigures& f) { return double(f.particles); }},
};

}  // namespace

void Metrics::set_session(const std::string& id, const SessionFigures& figures) {
  std::lock_guard lock(sessions_mutex_);
  session_figures_[id] = figures;
}

void Metrics::forget_session(const std::string& id) {
  std::lock_guard lock(sessions_mutex_);
  session_figures_.erase(id);
}

void Histogram::observe(double milliseconds) {
  std::size_t bucket = 0;
  while (bucket < kBounds.size() && milliseconds > kBounds[bucket]) ++bucket;
  std::lock_guard lock(mutex_);
  ++counts_[bucket];
  sum_ += milliseconds;
}

void Histogram::write(std::string& out, const std::string& name, const std::string& help) const {
  std::lock_guard lock(mutex_);
  out += "# HELP " + name + " " + help + "\n# TYPE " + name + " histogram\n";
  std::uint64_t cumulative = 0;
  for (std::size_t k = 0; k < kBounds.size(); ++k) {
    cumulative += counts_[k];
    out += name + "_bucket{le=\"" + number(kBounds[k]) + "\"} " + std::to_string(cumulative) + "\n";
  }
  cumulative += counts_.back();
  out += name + "_bucket{le=\"+Inf\"} " + std::to_string(cumulative) + "\n";
  out += name + "_sum " + number(sum_) + "\n";
  out += name + "_count " + std::to_string(cumulative) + "\n";
}

std::string Metrics::prometheus_text() const {
  std::string out;
  write_value(out, "fluidcast_sessions", "gauge", "Sessions alive.", sessions);
  write_value(out, "fluidcast_viewers", "gauge", "Viewers connected.", viewers);
  write_value(out, "fluidcast_frames_sent_total", "counter", "Frames handed to transports.",
              frames_sent);
  write_value(out, "fluidcast_frames_dropped_total", "counter",
              "Frames replaced by newer ones before a slow viewer read them.", frames_dropped);
  write_value(out, "fluidcast_frames_skipped_total", "counter",
              "Frames not rendered because the viewer had enough in flight.", frames_skipped);
  write_value(out, "fluidcast_frames_deferred_total", "counter",
              "Frames not rendered in a tick because their session had spent its share of the GPU "
              "while other sessions were watched.",
              frames_deferred);
  write_value(out, "fluidcast_bytes_sent_total", "counter", "JPEG bytes handed to transports.",
              bytes_sent);
  write_value(out, "fluidcast_streams_refused_total", "counter",
              "Streams ended with an error status for bad input or a limit.", streams_refused);
  write_value(out, "fluidcast_gpu_memory_bytes", "gauge", "GPU memory held by the allocator.",
              gpu_memory_bytes);
  sim_ms.write(out, "fluidcast_sim_milliseconds", "Simulation time per tick of a session.");
  render_ms.write(out, "fluidcast_render_milliseconds", "GPU time of a frame's render passes.");
  readback_ms.write(out, "fluidcast_readback_milliseconds", "GPU time of a frame's read-back.");
  encode_ms.write(out, "fluidcast_encode_milliseconds", "JPEG encoding time of a frame.");
  round_trip_ms.write(out, "fluidcast_round_trip_milliseconds",
                      "From a frame's production to the client's acknowledgement.");
  input_wait_ms.write(out, "fluidcast_input_wait_milliseconds",
                      "From an input's arrival to the start of the tick that drew its first frame.");
  queue_ms.write(out, "fluidcast_queue_milliseconds",
                 "From a frame's submission to the GPU until the server took it back.");
  encode_wait_ms.write(out, "fluidcast_encode_wait_milliseconds",
                       "A frame's wait for an encoder thread.");
  server_ms.write(out, "fluidcast_server_milliseconds",
                  "From the start of a frame's tick until it was handed to the transport.");
  send_ms.write(out, "fluidcast_send_milliseconds",
                "From a frame's hand-over to the transport until it was written.");
  std::lock_guard lock(sessions_mutex_);
  for (const SessionSeries& series : kSessionSeries) {
    out += "# HELP " + std::string(series.name) + " " + series.help + "\n# TYPE " + series.name +
           " gauge\n";
    for (const auto& [id, figures] : session_figures_) {
      out += std::string(series.name) + "{session=\"" + id + "\"} " +
             number(series.value(figures)) + "\n";
    }
  }
  return out;
}

}  // namespace fluidcast::server

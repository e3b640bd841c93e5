#include "metrics.h"

#include <fluidcast/version.h>

#include <cstdio>
#include <utility>

#include "fluidcast/gpu/context.h"

namespace fluidcast::server {
namespace {

std::string number(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.17g", value);
  return text;
}

// A label's value as the text format wants it: backslash, quote and newline escaped.
std::string quoted(const std::string& value) {
  std::string out = "\"";
  for (const char c : value) {
    if (c == '\\' || c == '"') out += '\\';
    out += c == '\n' ? std::string("\\n") : std::string(1, c);
  }
  return out + "\"";
}

void write_header(std::string& out, const std::string& name, const char* type,
                  const std::string& help) {
  out += "# HELP " + name + " " + help + "\n# TYPE " + name + " " + type + "\n";
}

void write_value(std::string& out, const std::string& name, const char* type,
                 const std::string& help, std::uint64_t value) {
  write_header(out, name, type, help);
  out += name + " " + std::to_string(value) + "\n";
}

void write_histogram(std::string& out, const Histogram& histogram, const std::string& name,
                     const std::string& help) {
  write_header(out, name, "histogram", help);
  histogram.write_series(out, name, "");
}

// The per-session gauges, labelled with the session's id.
struct SessionSeries {
  const char* name;
  const char* help;
  double (*value)(const SessionFigures&);
};
constexpr SessionSeries kSessionSeries[] = {
    {"fluidcast_session_sim_speed_ratio",
     "Simulated seconds per wall second over the last second (1: real time).",
     [](const SessionFigures& f) { return f.sim_speed; }},
    {"fluidcast_session_substep_seconds",
     "Measured cost of one solver substep (GPU time on a GPU solver).",
     [](const SessionFigures& f) { return f.substep_ms / 1000.0; }},
    {"fluidcast_session_frame_seconds",
     "Measured GPU time of one frame for each of the session's viewers, summed.",
     [](const SessionFigures& f) { return f.frame_ms / 1000.0; }},
    {"fluidcast_session_particles", "Particles in the session.",
     [](const SessionFigures& f) { return double(f.particles); }},
};

}  // namespace

const char* transport_name(Transport transport) {
  return transport == Transport::grpc ? "grpc" : "websocket";
}

void Histogram::observe_ms(double milliseconds) {
  const double seconds = milliseconds / 1000.0;
  std::size_t bucket = 0;
  while (bucket < kBoundsSeconds.size() && seconds > kBoundsSeconds[bucket]) ++bucket;
  std::lock_guard lock(mutex_);
  ++counts_[bucket];
  sum_seconds_ += seconds;
}

void Histogram::write_series(std::string& out, const std::string& name,
                             const std::string& labels) const {
  const std::string before_le = labels.empty() ? "{" : "{" + labels + ",";
  const std::string braced = labels.empty() ? "" : "{" + labels + "}";
  std::lock_guard lock(mutex_);
  std::uint64_t cumulative = 0;
  for (std::size_t k = 0; k < kBoundsSeconds.size(); ++k) {
    cumulative += counts_[k];
    out += name + "_bucket" + before_le + "le=\"" + number(kBoundsSeconds[k]) + "\"} " +
           std::to_string(cumulative) + "\n";
  }
  cumulative += counts_.back();
  out += name + "_bucket" + before_le + "le=\"+Inf\"} " + std::to_string(cumulative) + "\n";
  out += name + "_sum" + braced + " " + number(sum_seconds_) + "\n";
  out += name + "_count" + braced + " " + std::to_string(cumulative) + "\n";
}

void Metrics::describe_device(const gpu::DeviceInfo& device) {
  std::string labels = "device=" + quoted(device.name) +
                       ",type=" + quoted(device.hardware() ? "gpu" : "cpu") +
                       ",index=" + quoted(std::to_string(device.index)) +
                       ",uuid=" + quoted(device.uuid);
  std::lock_guard lock(mutex_);
  device_labels_ = std::move(labels);
}

void Metrics::refused(Transport transport, RefusalCode reason) {
  std::lock_guard lock(mutex_);
  ++refusals_[{transport, reason}];
}

void Metrics::sent(Transport transport, double milliseconds) {
  send_time_[static_cast<std::size_t>(transport)].observe_ms(milliseconds);
}

void Metrics::set_session(const std::string& id, const SessionFigures& figures) {
  std::lock_guard lock(mutex_);
  session_figures_[id] = figures;
}

void Metrics::forget_session(const std::string& id) {
  std::lock_guard lock(mutex_);
  session_figures_.erase(id);
}

std::string Metrics::prometheus_text() const {
  std::string out;
  write_totals(out);
  write_histograms(out);
  write_labelled(out);
  return out;
}

void Metrics::write_totals(std::string& out) const {
  write_header(out, "fluidcast_build_info", "gauge", "The server's version; always 1.");
  out += std::string("fluidcast_build_info{version=") + quoted(kVersion) + "} 1\n";
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
  write_value(out, "fluidcast_frames_on_floor_total", "counter",
              "Frames rendered though their session had spent its share of the GPU: a viewer's "
              "frame rate floor (once a second while the debt is small, one every five seconds "
              "per session however deep).",
              frames_on_floor);
  write_value(out, "fluidcast_sent_bytes_total", "counter", "JPEG bytes handed to transports.",
              bytes_sent);
  write_value(out, "fluidcast_gpu_memory_bytes", "gauge", "GPU memory held by the allocator.",
              gpu_memory_bytes);
}

void Metrics::write_histograms(std::string& out) const {
  write_histogram(out, sim_time, "fluidcast_sim_seconds", "Simulation time per tick of a session.");
  write_histogram(out, render_time, "fluidcast_render_seconds",
                  "GPU time of a frame's render passes.");
  write_histogram(out, readback_time, "fluidcast_readback_seconds",
                  "GPU time of a frame's read-back.");
  write_histogram(out, encode_time, "fluidcast_encode_seconds", "JPEG encoding time of a frame.");
  write_histogram(out, round_trip_time, "fluidcast_round_trip_seconds",
                  "From a frame's production to the client's acknowledgement.");
  write_histogram(out, input_wait_time, "fluidcast_input_wait_seconds",
                  "From an input's arrival to the start of the tick that drew its first frame.");
  write_histogram(out, queue_time, "fluidcast_queue_seconds",
                  "From a frame's submission to the GPU until the server took it back.");
  write_histogram(out, encode_wait_time, "fluidcast_encode_wait_seconds",
                  "A frame's wait for an encoder thread.");
  write_histogram(out, server_time, "fluidcast_server_seconds",
                  "From the start of a frame's tick until it was handed to the transport.");
  write_header(out, "fluidcast_send_seconds", "histogram",
               "From a frame's hand-over to the transport until it was written.");
  for (const Transport transport : kTransports) {
    send_time_[static_cast<std::size_t>(transport)].write_series(
        out, "fluidcast_send_seconds",
        std::string("transport=") + quoted(transport_name(transport)));
  }
}

// The series whose labels are known only at run time: under the lock that guards them.
void Metrics::write_labelled(std::string& out) const {
  std::lock_guard lock(mutex_);
  write_header(out, "fluidcast_device_info", "gauge",
               "The Vulkan device the server runs on (type: gpu, or cpu for a software device; "
               "index: what --device takes; uuid: the driver's, empty where it gives none); "
               "always 1.");
  out += "fluidcast_device_info{" + device_labels_ + "} 1\n";
  write_header(out, "fluidcast_streams_refused_total", "counter",
               "Streams the server ended with an error status (bad input, a limit, a failure, the "
               "idle timeout, shutdown), by transport and status code.");
  for (const auto& [key, count] : refusals_) {
    out += std::string("fluidcast_streams_refused_total{transport=") +
           quoted(transport_name(key.first)) + ",reason=" + quoted(refusal_code_name(key.second)) +
           "} " + std::to_string(count) + "\n";
  }
  for (const SessionSeries& series : kSessionSeries) {
    write_header(out, series.name, "gauge", series.help);
    for (const auto& [id, figures] : session_figures_) {
      out += std::string(series.name) + "{session=" + quoted(id) + "} " +
             number(series.value(figures)) + "\n";
    }
  }
}

}  // namespace fluidcast::server

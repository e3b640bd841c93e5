#include "headless_client.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "fluidcast/codec/jpeg.h"
#include "gesture_script.h"
#include "stream_client.h"

namespace fluidcast::client {
namespace {

using Clock = std::chrono::steady_clock;

double percentile(std::vector<double> values, double p) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const std::size_t index = std::min(values.size() - 1, std::size_t(p * double(values.size())));
  return values[index];
}

// Where each frame's time went on the server (v1::StageTimings), and how fast its fluid ran.
struct FrameFigures {
  std::vector<double> input_wait, sim, queue, render, readback, encode_wait, encode, server;
  // Input wait + server, for frames that show a new input: the part of its latency spent there.
  std::vector<double> on_server;
  std::vector<double> sim_speed;

  void add(const v1::Frame& frame) {
    const v1::StageTimings& t = frame.timings();
    if (t.input_wait_ms() > 0.0f) input_wait.push_back(t.input_wait_ms());
    sim.push_back(t.sim_ms());
    queue.push_back(t.queue_ms());
    render.push_back(t.render_ms());
    readback.push_back(t.readback_ms());
    encode_wait.push_back(t.encode_wait_ms());
    encode.push_back(t.encode_ms());
    server.push_back(t.server_ms());
    if (t.input_wait_ms() > 0.0f) on_server.push_back(t.input_wait_ms() + t.server_ms());
    sim_speed.push_back(frame.sim_speed());
  }

  nlohmann::json stages_p50() const {
    return {
        {"input_wait", percentile(input_wait, 0.5)}, {"sim", percentile(sim, 0.5)},
        {"queue", percentile(queue, 0.5)},           {"render", percentile(render, 0.5)},
        {"readback", percentile(readback, 0.5)},     {"encode_wait", percentile(encode_wait, 0.5)},
        {"encode", percentile(encode, 0.5)},         {"server", percentile(server, 0.5)}};
  }
};

}  // namespace

int run_headless(const HeadlessOptions& o) {
  const v1::Hello& hello = o.hello;
  const std::vector<ScriptedEvent> script =
      o.script.empty() ? default_gesture(o.seconds) : read_gesture_script(o.script);
  if (!o.save_frames.empty()) std::filesystem::create_directories(o.save_frames);

  StreamClient stream(connect(o.server), hello);
  std::fprintf(stderr, "fluidcast-client: %s\n", describe_welcome(stream.welcome()).c_str());
  const auto start = Clock::now();
  const auto end =
      start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(o.seconds));
  std::size_t next_event = 0, frames = 0, bytes = 0, bad_frames = 0;
  FrameFigures figures;
  while (Clock::now() < end && !stream.ended()) {
    const double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
    while (next_event < script.size() && script[next_event].time <= elapsed) {
      v1::ClientMessage message = script[next_event++].message;
      if (message.has_pointer()) {
        stream.pointer(message.pointer().pointer_id(), message.pointer().phase(),
                       message.pointer().x(), message.pointer().y());
      } else if (message.has_tilt()) {
        stream.tilt(message.tilt().x(), message.tilt().y(), message.tilt().z());
      } else {
        stream.command(message.command());
      }
    }
    const auto frame = stream.next_frame(std::chrono::milliseconds(5));
    if (!frame) continue;
    ++frames;
    bytes += frame->jpeg().size();
    figures.add(*frame);
    const auto& jpeg = frame->jpeg();
    try {
      const codec::ImageRgba image =
          codec::decode_jpeg({reinterpret_cast<const std::uint8_t*>(jpeg.data()), jpeg.size()});
      if (std::uint32_t(image.width) != frame->width() ||
          std::uint32_t(image.height) != frame->height()) {
        ++bad_frames;
      }
    } catch (const std::exception&) {
      ++bad_frames;
    }
    if (!o.save_frames.empty()) {
      char name[32];
      std::snprintf(name, sizeof name, "frame_%06llu.jpg",
                    static_cast<unsigned long long>(frame->sequence()));
      std::ofstream(std::filesystem::path(o.save_frames) / name, std::ios::binary)
          .write(jpeg.data(), static_cast<std::streamsize>(jpeg.size()));
    }
  }
  const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
  const bool ended_early = stream.ended();
  const grpc::Status status = ended_early ? stream.status() : stream.finish();
  const std::vector<double> latencies = stream.latencies_ms();
  nlohmann::json report = {
      {"frames", frames},
      {"bad_frames", bad_frames},
      {"seconds", seconds},
      {"fps", double(frames) / seconds},
      {"bitrate_kbps", 8.0 * double(bytes) / seconds / 1000.0},
      {"latency_samples", latencies.size()},
      {"latency_p50_ms", percentile(latencies, 0.50)},
      {"latency_p95_ms", percentile(latencies, 0.95)},
      {"latency_max_ms",
       latencies.empty() ? 0.0 : *std::max_element(latencies.begin(), latencies.end())},
      {"sim_speed_p50", percentile(figures.sim_speed, 0.5)},
      {"stages_p50_ms", figures.stages_p50()},
      // What the latency spent outside the server: the network both ways and this client.
      {"outside_server_p50_ms",
       std::max(0.0, percentile(latencies, 0.5) - percentile(figures.on_server, 0.5))},
      {"status", status.ok() ? "OK" : status.error_message()},
  };
  if (o.json) {
    std::printf("%s\n", report.dump().c_str());
  } else {
    std::printf(
        "%zu frames in %.1f s: %.1f fps, %.0f kbit/s; touch-to-photon p50 %.1f ms, p95 "
        "%.1f ms, max %.1f ms (%zu samples); simulation speed %.2f\n",
        frames, seconds, double(frames) / seconds, report["bitrate_kbps"].get<double>(),
        report["latency_p50_ms"].get<double>(), report["latency_p95_ms"].get<double>(),
        report["latency_max_ms"].get<double>(), latencies.size(),
        report["sim_speed_p50"].get<double>());
    std::printf("where the time went (p50 ms): %s\n", report["stages_p50_ms"].dump().c_str());
  }
  if (!status.ok()) {
    std::fprintf(stderr, "fluidcast-client: the stream ended: %s\n",
                 status.error_message().c_str());
    return 1;
  }
  return bad_frames == 0 ? 0 : 1;
}

}  // namespace fluidcast::client

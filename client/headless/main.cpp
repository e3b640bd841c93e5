// fluidcast-client --headless: connects to a server, plays a gesture script (or a default drag),
// decodes every frame, and reports frames, fps, bitrate and touch-to-photon latency. With --json
// its last line is one JSON object.
#include <CLI/CLI.hpp>
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

struct Options {
  bool headless = false;
  std::string server = "127.0.0.1:50051";
  std::uint32_t width = 320, height = 240, particles = 0, quality = 0, fps = 0;
  std::string scene, solver, renderer, token, join, script, save_frames;
  double seconds = 5.0;
  bool json = false, adaptive = false;
};

double percentile(std::vector<double> values, double p) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const std::size_t index = std::min(values.size() - 1, std::size_t(p * double(values.size())));
  return values[index];
}

int run(const Options& o) {
  v1::Hello hello;
  hello.set_token(o.token);
  hello.mutable_viewport()->set_width(o.width);
  hello.mutable_viewport()->set_height(o.height);
  hello.mutable_quality()->set_jpeg_quality(o.quality);
  hello.mutable_quality()->set_max_fps(o.fps);
  hello.mutable_quality()->set_renderer(o.renderer);
  hello.mutable_quality()->set_adaptive(o.adaptive);
  if (!o.join.empty()) {
    hello.set_join(o.join);
  } else {
    hello.mutable_create()->set_scene(o.scene);
    hello.mutable_create()->set_solver(o.solver);
    hello.mutable_create()->set_particles(o.particles);
  }
  const std::vector<ScriptedEvent> script =
      o.script.empty() ? default_gesture(o.seconds) : read_gesture_script(o.script);
  if (!o.save_frames.empty()) std::filesystem::create_directories(o.save_frames);

  StreamClient stream(connect(o.server), hello);
  std::fprintf(stderr, "fluidcast-client: session %s, viewer %u, %u particles\n",
               stream.welcome().session_id().c_str(), stream.welcome().viewer_id(),
               stream.welcome().state().particles());
  const auto start = Clock::now();
  const auto end = start + std::chrono::duration_cast<Clock::duration>(
                               std::chrono::duration<double>(o.seconds));
  std::size_t next_event = 0, frames = 0, bytes = 0, bad_frames = 0;
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
    const auto& jpeg = frame->jpeg();
    try {
      const codec::ImageRgba image = codec::decode_jpeg(
          {reinterpret_cast<const std::uint8_t*>(jpeg.data()), jpeg.size()});
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
      {"latency_max_ms", latencies.empty() ? 0.0 : *std::max_element(latencies.begin(), latencies.end())},
      {"status", status.ok() ? "OK" : status.error_message()},
  };
  if (o.json) {
    std::printf("%s\n", report.dump().c_str());
  } else {
    std::printf("%zu frames in %.1f s: %.1f fps, %.0f kbit/s; touch-to-photon p50 %.1f ms, p95 "
                "%.1f ms, max %.1f ms (%zu samples)\n",
                frames, seconds, double(frames) / seconds, report["bitrate_kbps"].get<double>(),
                report["latency_p50_ms"].get<double>(), report["latency_p95_ms"].get<double>(),
                report["latency_max_ms"].get<double>(), latencies.size());
  }
  if (!status.ok()) {
    std::fprintf(stderr, "fluidcast-client: the stream ended: %s\n", status.error_message().c_str());
    return 1;
  }
  return bad_frames == 0 ? 0 : 1;
}

}  // namespace
}  // namespace fluidcast::client

int main(int argc, char** argv) {
  fluidcast::client::Options o;
  CLI::App app{"fluidcast-client: watch and touch a fluidcast session"};
  app.option_defaults()->always_capture_default();
  app.add_flag("--headless", o.headless, "No window: play a script and report (the only mode so far)");
  app.add_option("--server", o.server, "HOST:PORT of the server's gRPC");
  app.add_option("--width", o.width, "Frame width, pixels");
  app.add_option("--height", o.height, "Frame height, pixels");
  app.add_option("--particles", o.particles, "Particles of a new session (0: server default)");
  app.add_option("--scene", o.scene, "Scene of a new session (server default when empty)");
  app.add_option("--solver", o.solver, "pbf or sph (server default when empty)");
  app.add_option("--renderer", o.renderer, "auto, ssfr, mc or points");
  app.add_option("--quality", o.quality, "JPEG quality 1-100 (0: server default)");
  app.add_option("--fps", o.fps, "Highest frame rate wanted (0: server's rate)");
  app.add_flag("--adaptive", o.adaptive, "Let the server lower quality and size to keep up");
  app.add_option("--token", o.token, "Token, when the server wants one")->envname("FLUIDCAST_TOKEN");
  app.add_option("--join", o.join, "Join this session instead of creating one");
  app.add_option("--script", o.script, "Gesture script (JSON; see gesture_script.h)");
  app.add_option("--seconds", o.seconds, "How long to stream")->check(CLI::Range(0.1, 86400.0));
  app.add_option("--save-frames", o.save_frames, "Write every frame received as JPEG here");
  app.add_flag("--json", o.json, "Last line: one JSON object with the figures");
  CLI11_PARSE(app, argc, argv);
  if (!o.headless) {
    std::fprintf(stderr, "fluidcast-client: the window client is not built yet; use --headless\n");
    return 2;
  }
  try {
    return fluidcast::client::run(o);
  } catch (const fluidcast::client::StreamError& e) {
    std::fprintf(stderr, "fluidcast-client: the server refused: %s\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fluidcast-client: %s\n", e.what());
    return 2;
  }
}

#include "headless_client.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>

#include "fluidcast/codec/jpeg.h"
#include "gesture_script.h"
#include "handoff_sides.h"
#include "stop_signals.h"
#include "stream_client.h"

namespace fluidcast::client {
namespace {

using Clock = std::chrono::steady_clock;

// Where each frame's time went on the server (v1::StageTimings), and how fast its fluid ran.
struct FrameFigures {
  std::size_t frames = 0, bytes = 0, bad_frames = 0;
  std::vector<double> input_wait, sim, queue, render, readback, encode_wait, encode, server;
  // Input wait + server, for frames that show a new input: the part of its latency spent there.
  std::vector<double> on_server;
  std::vector<double> sim_speed;

  void add(const v1::Frame& frame, bool decoded) {
    ++frames;
    bytes += frame.jpeg().size();
    if (!decoded) ++bad_frames;
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

// Sends what the script says until `elapsed`, from `next` on; returns the next event to send.
std::size_t play(FluidStream& stream, const std::vector<ScriptedEvent>& script, std::size_t next,
                 double elapsed) {
  for (; next < script.size() && script[next].time <= elapsed; ++next) {
    stream.send(script[next].message);
  }
  return next;
}

// Whether the frame's JPEG decodes to the size it says.
bool decodes(const v1::Frame& frame) {
  try {
    const codec::ImageRgba image = codec::decode_jpeg(
        {reinterpret_cast<const std::uint8_t*>(frame.jpeg().data()), frame.jpeg().size()});
    return std::uint32_t(image.width) == frame.width() &&
           std::uint32_t(image.height) == frame.height();
  } catch (const std::exception&) {
    return false;
  }
}

void save(const v1::Frame& frame, const std::string& folder) {
  char name[32];
  std::snprintf(name, sizeof name, "frame_%06llu.jpg",
                static_cast<unsigned long long>(frame.sequence()));
  std::ofstream(std::filesystem::path(folder) / name, std::ios::binary)
      .write(frame.jpeg().data(), static_cast<std::streamsize>(frame.jpeg().size()));
}

// The run's figures; without a stream (none opened), those of no frames.
nlohmann::json report_of(const FrameFigures& figures, const HandoffStream* stream, double seconds) {
  const std::vector<double> latencies = stream ? stream->latencies_ms() : std::vector<double>{};
  const auto handoff_gap_ms = stream ? stream->handoff_gap_ms() : std::nullopt;
  return {
      {"frames", figures.frames},
      {"bad_frames", figures.bad_frames},
      {"seconds", seconds},
      {"fps", double(figures.frames) / seconds},
      {"bitrate_kbps", 8.0 * double(figures.bytes) / seconds / 1000.0},
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
      // Where the fluid was at the end, and the gap of the newest handoff (null: none).
      {"simulated_here", stream && stream->simulating_here()},
      {"handoff_gap_ms", handoff_gap_ms ? nlohmann::json(*handoff_gap_ms) : nlohmann::json()},
  };
}

// The report as one JSON line, or as sentences; with how the stream ended.
void print(nlohmann::json report, const std::string& ended_because, bool json) {
  report["status"] = ended_because.empty() ? "OK" : ended_because;
  if (json) {
    std::printf("%s\n", report.dump().c_str());
    std::fflush(stdout);
    return;
  }
  std::printf(
      "%zu frames in %.1f s: %.1f fps, %.0f kbit/s; touch-to-photon p50 %.1f ms, p95 "
      "%.1f ms, max %.1f ms (%zu samples); simulation speed %.2f\n",
      report["frames"].get<std::size_t>(), report["seconds"].get<double>(),
      report["fps"].get<double>(), report["bitrate_kbps"].get<double>(),
      report["latency_p50_ms"].get<double>(), report["latency_p95_ms"].get<double>(),
      report["latency_max_ms"].get<double>(), report["latency_samples"].get<std::size_t>(),
      report["sim_speed_p50"].get<double>());
  std::printf("where the time went (p50 ms): %s\n", report["stages_p50_ms"].dump().c_str());
  std::fflush(stdout);  // before a goodbye that a second Ctrl-C may cut short
}

}  // namespace

int run_headless(const HeadlessOptions& o) {
  const std::vector<ScriptedEvent> script =
      o.script.empty() ? default_gesture(o.seconds) : read_gesture_script(o.script);
  if (!o.save_frames.empty()) std::filesystem::create_directories(o.save_frames);

  HandoffOptions handoff;
  handoff.handoff = handoff.retry = o.handoff;
  handoff.max_local_particles = o.max_local_particles;
  handoff.say = [](const std::string& line) {
    std::fprintf(stderr, "fluidcast-client: %s\n", line.c_str());
  };
  StopSignals stop;  // before the stream starts its threads
  handoff.stop = stop.stop_token();
  const auto stopped = [&stop] {
    return "stopped by SIG" + std::string(sigabbrev_np(stop.received()));
  };
  std::optional<HandoffStream> opened;
  const auto asked = Clock::now();
  // A run that never streamed still ends with --json's report as its last line, saying why.
  const auto report_unopened = [&](const std::string& why) {
    if (!o.json) return;
    print(report_of({}, nullptr, std::chrono::duration<double>(Clock::now() - asked).count()), why,
          true);
  };
  try {
    opened.emplace(o.hello, handoff_sides(o.server, o.max_local_particles), handoff);
  } catch (const StreamError& e) {
    if (e.code() == grpc::StatusCode::CANCELLED && stop.received()) {
      report_unopened(stopped() + " while connecting");
      std::fprintf(stderr, "fluidcast-client: %s while connecting\n", stopped().c_str());
      return 128 + stop.received();
    }
    report_unopened(std::string("the server refused: ") + e.what());
    throw;
  } catch (const Unreachable& e) {
    report_unopened(std::string("cannot connect: ") + e.what());
    throw;
  }
  HandoffStream& stream = *opened;
  if (!stream.welcome().session_id().empty()) {  // else it is still asking (--handoff)
    std::fprintf(stderr, "fluidcast-client: %s\n", describe_welcome(stream.welcome()).c_str());
  }
  const auto start = Clock::now();
  const auto end =
      start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(o.seconds));
  std::size_t next_event = 0;
  FrameFigures figures;
  while (Clock::now() < end && !stream.ended() && !stop.received()) {
    next_event = play(stream, script, next_event,
                      std::chrono::duration<double>(Clock::now() - start).count());
    const auto frame = stream.next_frame(std::chrono::milliseconds(5));
    if (!frame) continue;
    figures.add(*frame, decodes(*frame));
    if (!o.save_frames.empty()) save(*frame, o.save_frames);
  }
  const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
  const nlohmann::json report = report_of(figures, &stream, seconds);
  if (stop.received()) {
    // Its figures, cut short, said before the goodbye (which a second signal may cut short), and
    // the status a shell gives a run that signal ended.
    print(report, stopped(), o.json);
    stream.close();
    return 128 + stop.received();
  }
  const std::string ended_because = stream.close();
  print(report, ended_because, o.json);
  if (!ended_because.empty()) {
    std::fprintf(stderr, "fluidcast-client: the stream ended: %s\n", ended_because.c_str());
    return 1;
  }
  return figures.bad_frames == 0 ? 0 : 1;
}

}  // namespace fluidcast::client

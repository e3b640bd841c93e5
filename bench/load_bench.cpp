// The load test: N headless clients, each with its own session, against one fluidcast-server on
// loopback for S seconds. Prints a Markdown table (per client: fps, touch-to-photon percentiles,
// simulation speed, GPU milliseconds per frame; server memory) and exits 1 when a client got no
// frames, a stream failed, or the server's memory grew past --max-growth-mb after the first
// quarter of the run. Figures are taken after --warm-up seconds (pipelines compiled, costs
// measured).
//   fluidcast-bench-load [--clients 8] [--seconds 30] [--warm-up 3] [--width 320] [--height 240]
//                        [--particles 1000] [--scene dam_break] [--renderer auto]
//                        [--server-flag=--backend=gpu ...]
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <mutex>
#include <thread>

#include "dragging_viewer.h"
#include "fluidcast/command_line.h"
#include "server_process.h"

namespace fluidcast {
namespace {

using testing::percentile;
using testing::ViewerRun;

struct Options {
  unsigned clients = 8, width = 320, height = 240, particles = 1000;
  double seconds = 30.0, warm_up = 3.0, max_growth_mb = 64.0;
  std::string scene, renderer;
  std::vector<std::string> server_flags;
};

// The server's resident memory, KiB: after a quarter of the run (sessions built, windows full),
// and the peak after it.
struct Memory {
  long warm_kb = 0, peak_kb = 0;
};

// One line per client and a summary; false when a client or the memory bound failed.
bool report(const Options& o, const std::vector<ViewerRun>& results, Memory memory,
            int server_exit) {
  std::printf(
      "| client | frames | fps | kbit/s | latency p50 ms | p95 ms | max ms | sim speed | "
      "GPU ms/frame | sim ms/frame | error |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|\n");
  bool failed = server_exit != 0;
  std::vector<double> all, fps;
  for (unsigned k = 0; k < o.clients; ++k) {
    const ViewerRun& r = results[k];
    all.insert(all.end(), r.latencies_ms.begin(), r.latencies_ms.end());
    fps.push_back(r.fps());
    std::printf("| %u | %zu | %.1f | %.0f | %.0f | %.0f | %.0f | %.3f | %.2f | %.2f | %s |\n", k,
                r.frames, fps.back(), 8.0 * double(r.bytes) / o.seconds / 1000.0,
                percentile(r.latencies_ms, 0.5), percentile(r.latencies_ms, 0.95),
                r.latencies_ms.empty()
                    ? 0.0
                    : *std::max_element(r.latencies_ms.begin(), r.latencies_ms.end()),
                percentile(r.sim_speed, 0.5), percentile(r.gpu_ms, 0.5), percentile(r.sim_ms, 0.5),
                r.error.empty() ? "" : r.error.c_str());
    failed = failed || r.frames == 0 || !r.error.empty();
  }
  const double growth_mb = double(memory.peak_kb - memory.warm_kb) / 1024.0;
  std::printf(
      "\n%u clients × %.0f s (after %.0f s warm-up) at %ux%u, %u particles each (%s): fps per "
      "client min %.1f, median %.1f; latency over all p50 %.0f ms, p95 %.0f ms; server "
      "resident memory %.0f MB after warm-up, peak %.0f MB (growth %.1f MB, allowed %.0f); "
      "server exit %d\n",
      o.clients, o.seconds, o.warm_up, o.width, o.height, o.particles,
      o.scene.empty() ? "the server's scene" : o.scene.c_str(),
      *std::min_element(fps.begin(), fps.end()), percentile(fps, 0.5), percentile(all, 0.5),
      percentile(all, 0.95), double(memory.warm_kb) / 1024.0, double(memory.peak_kb) / 1024.0,
      growth_mb, o.max_growth_mb, server_exit);
  return !failed && growth_mb <= o.max_growth_mb;
}

int run(int argc, char** argv) {
  Options o;
  CLI::App app{"fluidcast-bench-load: N clients against one server on loopback"};
  app.add_option("--clients", o.clients)->check(CLI::Range(1u, 256u));
  app.add_option("--seconds", o.seconds, "Seconds measured, after the warm-up")
      ->check(CLI::Range(1.0, 3600.0));
  app.add_option("--warm-up", o.warm_up, "Seconds streamed before measuring")
      ->check(CLI::Range(0.0, 600.0));
  app.add_option("--scene", o.scene,
                 "dam_break, double_dam_break, drop or pool (the server's default: dam_break)");
  app.add_option("--renderer", o.renderer, "auto, ssfr, mc or points (the server's default: auto)");
  app.add_option("--width", o.width);
  app.add_option("--height", o.height);
  app.add_option("--particles", o.particles);
  app.add_option("--max-growth-mb", o.max_growth_mb, "Server memory growth allowed after warm-up");
  app.add_option("--server-flag", o.server_flags, "A flag for fluidcast-server (repeatable)");
  add_version_flag(app, "fluidcast-bench-load");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return exit_for(app, e);
  }
  // Every client comes from loopback: one address.
  o.server_flags.insert(o.server_flags.end(),
                        {"--max-sessions", std::to_string(o.clients), "--max-sessions-per-address",
                         std::to_string(o.clients)});
  testing::ServerProcess server(o.server_flags);
  v1::Hello hello;
  hello.mutable_viewport()->set_width(o.width);
  hello.mutable_viewport()->set_height(o.height);
  hello.mutable_create()->set_particles(o.particles);
  if (!o.scene.empty()) hello.mutable_create()->set_scene(o.scene);
  if (!o.renderer.empty()) hello.mutable_quality()->set_renderer(o.renderer);

  std::vector<ViewerRun> results(o.clients);
  std::vector<std::thread> threads;
  std::atomic<unsigned> finished{0};
  for (unsigned k = 0; k < o.clients; ++k) {
    threads.emplace_back([&, k] {
      results[k] = testing::run_dragging_viewer(server.grpc_address(), hello, o.warm_up, o.seconds);
      ++finished;
    });
  }
  std::this_thread::sleep_for(std::chrono::duration<double>(o.warm_up + o.seconds / 4));
  Memory memory{server.resident_kb(), 0};
  memory.peak_kb = memory.warm_kb;
  while (finished < o.clients) {
    memory.peak_kb = std::max(memory.peak_kb, server.resident_kb());
    std::this_thread::sleep_for(std::chrono::milliseconds(250));
  }
  for (auto& thread : threads) thread.join();
  const int server_exit = server.stop();
  const bool passed = report(o, results, memory, server_exit);
  std::printf("%s\n", passed ? "passed" : "FAILED");
  return passed ? 0 : 1;
}

}  // namespace
}  // namespace fluidcast

int main(int argc, char** argv) { return fluidcast::run(argc, argv); }

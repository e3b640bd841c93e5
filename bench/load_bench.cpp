// The load test: N headless clients, each with its own session, against one fluidcast-server on
// loopback for S seconds. Prints a Markdown table (per client: fps, touch-to-photon percentiles,
// simulation speed, GPU milliseconds per frame; server memory) and exits 1 when a client got no
// frames, a stream failed, or the server's memory grew past --max-growth-mb after the first
// quarter of the run. Figures are taken after --warm-up seconds (pipelines compiled, costs
// measured).
//   fluidcast-bench-load [--clients 8] [--seconds 30] [--warm-up 3] [--width 320] [--height 240]
//                        [--particles 1000] [--renderer auto] [--server-flag=--backend=gpu ...]
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <mutex>
#include <thread>

#include "fluidcast/command_line.h"
#include "dragging_viewer.h"
#include "server_process.h"

namespace fluidcast {
namespace {

using testing::percentile;
using testing::ViewerRun;

int run(int argc, char** argv) {
  unsigned clients = 8, width = 320, height = 240, particles = 1000;
  double seconds = 30.0, warm_up = 3.0, max_growth_mb = 64.0;
  std::string renderer;
  std::vector<std::string> server_flags;
  CLI::App app{"fluidcast-bench-load: N clients against one server on loopback"};
  app.add_option("--clients", clients)->check(CLI::Range(1u, 256u));
  app.add_option("--seconds", seconds, "Seconds measured, after the warm-up")
      ->check(CLI::Range(1.0, 3600.0));
  app.add_option("--warm-up", warm_up, "Seconds streamed before measuring")
      ->check(CLI::Range(0.0, 600.0));
  app.add_option("--renderer", renderer, "auto, ssfr, mc or points (the server's default: auto)");
  app.add_option("--width", width);
  app.add_option("--height", height);
  app.add_option("--particles", particles);
  app.add_option("--max-growth-mb", max_growth_mb, "Server memory growth allowed after warm-up");
  app.add_option("--server-flag", server_flags, "A flag for fluidcast-server (repeatable)");
  add_version_flag(app, "fluidcast-bench-load");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return exit_for(app, e);
  }

  // Every client comes from loopback: one address.
  server_flags.insert(server_flags.end(), {"--max-sessions", std::to_string(clients),
                                           "--max-sessions-per-address", std::to_string(clients)});
  testing::ServerProcess server(server_flags);
  v1::Hello hello;
  hello.mutable_viewport()->set_width(width);
  hello.mutable_viewport()->set_height(height);
  hello.mutable_create()->set_particles(particles);
  if (!renderer.empty()) hello.mutable_quality()->set_renderer(renderer);

  std::vector<ViewerRun> results(clients);
  std::vector<std::thread> threads;
  std::atomic<unsigned> finished{0};
  for (unsigned k = 0; k < clients; ++k) {
    threads.emplace_back([&, k] {
      results[k] = testing::run_dragging_viewer(server.grpc_address(), hello, warm_up, seconds);
      ++finished;
    });
  }
  // Memory: after a quarter of the run (sessions built, windows full), then the peak after it.
  std::this_thread::sleep_for(std::chrono::duration<double>(warm_up + seconds / 4));
  const long warm_kb = server.resident_kb();
  long peak_kb = warm_kb;
  while (finished < clients) {
    peak_kb = std::max(peak_kb, server.resident_kb());
    std::this_thread::sleep_for(std::chrono::milliseconds(250));
  }
  for (auto& thread : threads) thread.join();
  const int server_exit = server.stop();

  std::printf("| client | frames | fps | kbit/s | latency p50 ms | p95 ms | max ms | sim speed | "
              "GPU ms/frame | sim ms/frame | error |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|\n");
  bool failed = server_exit != 0;
  std::vector<double> all, fps;
  for (unsigned k = 0; k < clients; ++k) {
    const ViewerRun& r = results[k];
    all.insert(all.end(), r.latencies_ms.begin(), r.latencies_ms.end());
    fps.push_back(r.fps());
    std::printf("| %u | %zu | %.1f | %.0f | %.0f | %.0f | %.0f | %.3f | %.2f | %.2f | %s |\n", k,
                r.frames, fps.back(), 8.0 * double(r.bytes) / seconds / 1000.0,
                percentile(r.latencies_ms, 0.5), percentile(r.latencies_ms, 0.95),
                r.latencies_ms.empty() ? 0.0 : *std::max_element(r.latencies_ms.begin(), r.latencies_ms.end()),
                percentile(r.sim_speed, 0.5), percentile(r.gpu_ms, 0.5), percentile(r.sim_ms, 0.5),
                r.error.empty() ? "" : r.error.c_str());
    failed = failed || r.frames == 0 || !r.error.empty();
  }
  const double growth_mb = double(peak_kb - warm_kb) / 1024.0;
  std::printf("\n%u clients × %.0f s (after %.0f s warm-up) at %ux%u, %u particles each: fps per "
              "client min %.1f, median %.1f; latency over all p50 %.0f ms, p95 %.0f ms; server "
              "resident memory %.0f MB after warm-up, peak %.0f MB (growth %.1f MB, allowed %.0f); "
              "server exit %d\n",
              clients, seconds, warm_up, width, height, particles,
              *std::min_element(fps.begin(), fps.end()), percentile(fps, 0.5), percentile(all, 0.5),
              percentile(all, 0.95), double(warm_kb) / 1024.0, double(peak_kb) / 1024.0, growth_mb,
              max_growth_mb, server_exit);
  failed = failed || growth_mb > max_growth_mb;
  std::printf("%s\n", failed ? "FAILED" : "passed");
  return failed ? 1 : 0;
}

}  // namespace
}  // namespace fluidcast

int main(int argc, char** argv) { return fluidcast::run(argc, argv); }

// The soak test: one server on loopback, a bystander (from ::1) streaming its own session
// throughout, and --clients workers (from 127.0.0.1) doing a random mix of what clients do and what
// they must not — create, join by key, leave, drop and resume, resize in bursts, send bad input,
// flood, put a clumped snapshot, open a stream and say nothing, stream without acknowledging — for
// --seconds. Then the server is left alone until every session has ended, and its memory,
// descriptors and threads are compared with where they were before the mix. Prints a Markdown
// table; exits 1 when the bystander's frame rate fell below half its rate alone in some 5-second
// window, when a worker's refusal came with a status other than the one its case documents, or when
// the server did not come back to its baseline (descriptors exactly; threads by name exactly, but
// for gRPC's pools, bounded by the cores; memory within --max-growth-mb).
//   fluidcast-bench-soak [--seconds 600] [--clients 4] [--seed N] [--max-growth-mb 64]
//                        [--case NAME ...]
#include <grpcpp/grpcpp.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <map>
#include <mutex>
#include <random>
#include <thread>
#include <tuple>
#include <utility>

#include "dragging_viewer.h"
#include "fluidcast/command_line.h"
#include "fluidcast/v1/fluidcast.grpc.pb.h"
#include "server_process.h"
#include "stream_client.h"

namespace fluidcast {
namespace {

using Clock = std::chrono::steady_clock;
using client::StreamClient;
using client::StreamError;
using std::chrono::milliseconds;

constexpr int kResumeGraceSeconds = 5;

v1::Hello hello_for(std::uint32_t particles, std::uint32_t width, std::uint32_t height) {
  v1::Hello hello;
  hello.mutable_viewport()->set_width(width);
  hello.mutable_viewport()->set_height(height);
  hello.mutable_create()->set_particles(particles);
  return hello;
}

// What each case did, and refusals that were not the one documented for it.
struct Tally {
  std::mutex mutex;
  std::map<std::string, int> cases;
  std::vector<std::string> wrong;
  void count(const std::string& name) {
    std::lock_guard lock(mutex);
    ++cases[name];
  }
  void unexpected(const std::string& what) {
    std::lock_guard lock(mutex);
    if (wrong.size() < 20) wrong.push_back(what);
  }
};

void drain(StreamClient& stream, double seconds) {
  const auto end = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                      std::chrono::duration<double>(seconds));
  while (Clock::now() < end && !stream.ended()) stream.next_frame(milliseconds(20));
}

// A stream that must end with `code` after `message`.
void expect_end(const std::string& address, const v1::ClientMessage& message, grpc::StatusCode code,
                const std::string& name, Tally& tally) {
  try {
    StreamClient stream(client::connect(address), hello_for(300, 96, 64));
    stream.send_raw(message);
    for (int k = 0; k < 100 && !stream.ended(); ++k) stream.next_frame(milliseconds(50));
    if (stream.status().error_code() != code) {
      tally.unexpected(name + ": " + std::to_string(stream.status().error_code()) + " " +
                       stream.status().error_message());
    }
  } catch (const StreamError& e) {
    if (e.code() != grpc::StatusCode::RESOURCE_EXHAUSTED) tally.unexpected(name + ": " + e.what());
  }
}

// One case of the soak: what a client does, and what it checks the server answered.
struct Case {
  const std::string& address;
  std::mt19937_64& random;
  Tally& tally;
};

void create_drag_goodbye(Case& c) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  StreamClient stream(client::connect(c.address), hello_for(200 + c.random() % 1500, 160, 120));
  stream.pointer(0, v1::PointerEvent::DOWN, 0.5f, 0.7f);
  for (int k = 0; k < 10; ++k) {
    stream.pointer(0, v1::PointerEvent::MOVE, float(unit(c.random)), 0.7f);
    drain(stream, 0.05);
  }
  stream.finish();
}

// Creates, drops, resumes, and watches with the view key.
void drop_resume_join(Case& c) {
  auto stream = std::make_unique<StreamClient>(client::connect(c.address), hello_for(500, 128, 96));
  const v1::Access access = stream->welcome().access();
  drain(*stream, 0.3);
  stream->drop();
  stream.reset();
  v1::Hello resume = hello_for(0, 128, 96);
  resume.mutable_resume()->set_key(access.resume_key());
  StreamClient back(client::connect(c.address), resume);
  v1::Hello watch = hello_for(0, 96, 64);
  watch.set_join(access.view_key());
  StreamClient watcher(client::connect(c.address), watch);
  drain(watcher, 0.3);
  watcher.finish();
  back.finish();
}

void resize_burst(Case& c) {
  StreamClient stream(client::connect(c.address), hello_for(400, 160, 120));
  for (int k = 0; k < 40; ++k) {
    v1::Command resize;
    resize.mutable_viewport()->set_width(k % 2 ? 1280 : 16);
    resize.mutable_viewport()->set_height(k % 2 ? 720 : 16);
    stream.command(resize);
    drain(stream, 0.02);
  }
  stream.finish();
}

void nan_pointer(Case& c) {
  v1::ClientMessage nan;
  nan.mutable_pointer()->set_phase(v1::PointerEvent::DOWN);
  nan.mutable_pointer()->set_x(std::nanf(""));
  expect_end(c.address, nan, grpc::StatusCode::INVALID_ARGUMENT, "NaN pointer", c.tally);
}

void input_flood(Case& c) {
  StreamClient stream(client::connect(c.address), hello_for(300, 96, 64));
  for (int k = 0; k < 1000 && !stream.ended(); ++k) {  // within the client's own queue
    stream.pointer(0, v1::PointerEvent::MOVE, 0.5f, 0.5f);
  }
  for (int k = 0; k < 100 && !stream.ended(); ++k) stream.next_frame(milliseconds(50));
  if (stream.status().error_code() != grpc::StatusCode::RESOURCE_EXHAUSTED) {
    c.tally.unexpected("input flood: " + stream.status().error_message());
  }
}

// A clumped snapshot into its own session.
void clumped_snapshot(Case& c) {
  StreamClient stream(client::connect(c.address), hello_for(2000, 96, 64));
  v1::PutSnapshotRequest put;
  put.set_key(stream.welcome().access().control_key());
  v1::Snapshot& clump = *put.mutable_snapshot();
  const v1::Box& tank = stream.welcome().state().tank();
  for (int k = 0; k < 2000; ++k) {
    clump.add_positions(0.5f * (tank.min().x() + tank.max().x()));
    clump.add_positions(0.5f * (tank.min().y() + tank.max().y()));
    clump.add_positions(0.5f * (tank.min().z() + tank.max().z()));
    for (int axis = 0; axis < 3; ++axis) clump.add_velocities(0.0f);
  }
  grpc::ClientContext context;
  v1::PutSnapshotReply reply;
  const grpc::Status status =
      v1::Fluidcast::NewStub(client::connect(c.address))->PutSnapshot(&context, put, &reply);
  if (status.error_code() != grpc::StatusCode::INVALID_ARGUMENT) {
    c.tally.unexpected("clumped snapshot: " + status.error_message());
  }
  stream.finish();
}

// A stream that never says Hello (the server's --hello-timeout is 2 s).
void no_hello(Case& c) {
  auto stub = v1::Fluidcast::NewStub(client::connect(c.address));
  grpc::ClientContext context;
  auto stream = stub->Stream(&context);
  v1::ServerMessage ignored;
  while (stream->Read(&ignored)) {
  }
  if (stream->Finish().error_code() != grpc::StatusCode::DEADLINE_EXCEEDED) {
    c.tally.unexpected("no Hello: not DEADLINE_EXCEEDED");
  }
}

// Streams without acknowledging, then cancels.
void no_acknowledgements(Case& c) {
  auto stub = v1::Fluidcast::NewStub(client::connect(c.address));
  grpc::ClientContext context;
  auto stream = stub->Stream(&context);
  v1::ClientMessage hello;
  *hello.mutable_hello() = hello_for(500, 640, 480);
  stream->Write(hello);
  v1::ServerMessage ignored;
  const auto until = Clock::now() + std::chrono::seconds(1);
  while (Clock::now() < until && stream->Read(&ignored)) {
  }
  context.TryCancel();
}

// A watcher that tries to control.
void watcher_tilts(Case& c) {
  StreamClient owner(client::connect(c.address), hello_for(300, 96, 64));
  v1::Hello watch = hello_for(0, 96, 64);
  watch.set_join(owner.welcome().access().view_key());
  StreamClient watcher(client::connect(c.address), watch);
  v1::ClientMessage tilt;
  tilt.mutable_tilt()->set_y(-9.81f);
  watcher.send_raw(tilt);
  for (int k = 0; k < 100 && !watcher.ended(); ++k) watcher.next_frame(milliseconds(50));
  if (watcher.status().error_code() != grpc::StatusCode::PERMISSION_DENIED) {
    c.tally.unexpected("watcher tilts: " + watcher.status().error_message());
  }
  owner.finish();
}

constexpr std::array<std::pair<const char*, void (*)(Case&)>, 9> kCases{{
    {"create, drag, goodbye", create_drag_goodbye},
    {"drop, resume, join by key", drop_resume_join},
    {"resize burst", resize_burst},
    {"NaN pointer", nan_pointer},
    {"input flood", input_flood},
    {"clumped snapshot", clumped_snapshot},
    {"no Hello", no_hello},
    {"no acknowledgements", no_acknowledgements},
    {"watcher tilts", watcher_tilts},
}};

using CaseList = std::vector<std::pair<const char*, void (*)(Case&)>>;

void worker(const std::string& address, const CaseList& cases, std::uint64_t seed,
            Clock::time_point end, Tally& tally) {
  std::mt19937_64 random(seed);
  Case c{address, random, tally};
  while (Clock::now() < end) {
    const auto& [name, run] = cases[random() % cases.size()];
    tally.count(name);
    try {
      run(c);
    } catch (const StreamError& e) {
      // The server at its session limit refuses a new one: documented, not a failure.
      if (e.code() != grpc::StatusCode::RESOURCE_EXHAUSTED) {
        tally.unexpected(std::string(name) + ": " + e.what());
      }
    }
  }
}

// What a viewer that drags through its fluid saw: frames per 5-second window, and the GPU time
// of each frame (render passes and read-back, as the server measured them): on lavapipe the
// "device" is the same two cores as everything else, so a frame's GPU time grows with the load,
// and the fair share charges it that way.
struct BystanderFigures {
  std::vector<double> windows;
  std::vector<double> frame_gpu_ms;
};

BystanderFigures bystander_windows(const std::string& address, const std::atomic<bool>& stop,
                                   std::string& error) {
  BystanderFigures figures;
  std::vector<double>& windows = figures.windows;
  try {
    StreamClient stream(client::connect(address), hello_for(1000, 320, 240));
    drain(stream, 2.0);  // pipelines compiled, costs measured
    auto window_start = Clock::now();
    int frames = 0;
    double t = 0.0;
    stream.pointer(0, v1::PointerEvent::DOWN, 0.5f, 0.6f);
    while (!stop && !stream.ended()) {
      t += 0.05;
      stream.pointer(0, v1::PointerEvent::MOVE, 0.5f + 0.3f * float(std::sin(t)), 0.6f);
      const auto next = Clock::now() + milliseconds(50);
      while (Clock::now() < next) {
        const auto frame = stream.next_frame(milliseconds(10));
        if (!frame) continue;
        ++frames;
        figures.frame_gpu_ms.push_back(frame->timings().render_ms() +
                                       frame->timings().readback_ms());
      }
      if (Clock::now() - window_start >= std::chrono::seconds(5)) {
        windows.push_back(frames /
                          std::chrono::duration<double>(Clock::now() - window_start).count());
        frames = 0;
        window_start = Clock::now();
      }
    }
    if (stream.ended()) error = stream.status().error_message();
    stream.finish();
  } catch (const std::exception& e) {
    error = e.what();
  }
  return figures;
}

// The bystander over 15 s with the server to itself: its mean frame rate, and its frames' GPU
// time.
std::pair<double, std::vector<double>> bystander_alone(const std::string& address,
                                                       std::string& error) {
  std::atomic<bool> stop{false};
  std::thread timer([&] {
    std::this_thread::sleep_for(std::chrono::seconds(17));
    stop = true;
  });
  const BystanderFigures figures = bystander_windows(address, stop, error);
  timer.join();
  double fps = 0.0;
  for (double window : figures.windows) fps += window / double(figures.windows.size());
  return {fps, figures.frame_gpu_ms};
}

// What the soak measured of the server and of the bystander.
struct Figures {
  double alone_fps = 0.0;                        // the bystander's, before the mix
  std::vector<double> alone_frame_gpu_ms;        // its frames' GPU time then
  BystanderFigures during;                       // per 5 s window, and per frame, during the mix
  std::array<long, 3> rss_kb{};                  // before, peak during, after
  std::array<long, 2> descriptors{}, threads{};  // before, after
  std::array<std::map<std::string, int>, 2> thread_names;  // before, after
  std::string bystander_error;                             // why its stream ended, if it did
};

// Whether the server's threads are back to where they were: ours by name exactly; gRPC's pools
// (its executor, two threads a core at most, its timer and event-engine threads) start threads as
// work queues up and keep them, so theirs may stay grown, by at most two a core in all.
bool threads_back(const std::array<std::map<std::string, int>, 2>& names) {
  // Their names as the kernel keeps them (15 characters).
  constexpr std::array<const char*, 4> kGrpcPools{"default-executo", "resolver-execut",
                                                  "grpc_global_tim", "event_engine"};
  auto ours = names;
  int grpc_growth = 0;
  for (const char* pool : kGrpcPools) {
    for (int k = 0; k < 2; ++k) {
      const auto found = ours[k].find(pool);
      if (found == ours[k].end()) continue;
      grpc_growth += k == 1 ? found->second : -found->second;
      ours[k].erase(found);
    }
  }
  return ours[0] == ours[1] &&
         grpc_growth <= 2 * static_cast<int>(std::thread::hardware_concurrency());
}

// The tables and the verdict: false when a figure fails.
bool report(const Figures& f, const Tally& tally, double max_growth_mb) {
  const std::vector<double>& windows = f.during.windows;
  const double worst = windows.empty() ? 0.0 : *std::min_element(windows.begin(), windows.end());
  std::printf("| case | times |\n| --- | --- |\n");
  for (const auto& [name, count] : tally.cases) std::printf("| %s | %d |\n", name.c_str(), count);
  std::printf("\n| figure | before | during | after |\n| --- | --- | --- | --- |\n");
  const auto below_half = std::count_if(windows.begin(), windows.end(),
                                        [&](double fps) { return fps < 0.5 * f.alone_fps; });
  std::printf(
      "| bystander fps (5 s windows) | %.1f alone | worst %.1f, median %.1f of %zu windows; %zu "
      "below half | |\n",
      f.alone_fps, worst, testing::percentile(windows, 0.5), windows.size(),
      static_cast<std::size_t>(below_half));
  std::printf("| bystander frame GPU ms (median) | %.1f alone | %.1f | |\n",
              testing::percentile(f.alone_frame_gpu_ms, 0.5),
              testing::percentile(f.during.frame_gpu_ms, 0.5));
  std::printf("| server memory (MB) | %.1f | peak %.1f | %.1f |\n", f.rss_kb[0] / 1024.0,
              f.rss_kb[1] / 1024.0, f.rss_kb[2] / 1024.0);
  std::printf("| descriptors | %ld | | %ld |\n", f.descriptors[0], f.descriptors[1]);
  std::map<std::string, int> change;  // which threads came or went, by name
  for (const auto& [name, count] : f.thread_names[1]) change[name] += count;
  for (const auto& [name, count] : f.thread_names[0]) change[name] -= count;
  std::string changed;
  for (const auto& [name, count] : change) {
    if (count != 0) changed += (count > 0 ? " +" : " ") + std::to_string(count) + " " + name;
  }
  std::printf("| threads | %ld | | %ld%s |\n", f.threads[0], f.threads[1], changed.c_str());
  bool failed = false;
  auto fail = [&](const std::string& why) {
    std::printf("FAIL: %s\n", why.c_str());
    failed = true;
  };
  if (!f.bystander_error.empty()) fail("the bystander's stream ended: " + f.bystander_error);
  if (worst < 0.5 * f.alone_fps) fail("the bystander fell below half its frame rate alone");
  for (const auto& wrong : tally.wrong) fail("unexpected: " + wrong);
  if (f.descriptors[1] != f.descriptors[0]) fail("descriptors not back to their baseline");
  if (!threads_back(f.thread_names)) fail("threads not back to their baseline");
  if ((f.rss_kb[2] - f.rss_kb[0]) / 1024.0 > max_growth_mb)
    fail("memory grew past --max-growth-mb");
  return !failed;
}

int run(int argc, char** argv) {
  unsigned clients = 4;
  double seconds = 600.0, max_growth_mb = 64.0;
  std::uint64_t seed = std::random_device{}();
  CLI::App app{"fluidcast-bench-soak: a random mix of clients, good and bad, beside a bystander"};
  app.add_option("--seconds", seconds, "Seconds of the mix")->check(CLI::Range(10.0, 86400.0));
  app.add_option("--clients", clients, "Workers at once")->check(CLI::Range(1u, 32u));
  app.add_option("--seed", seed, "For the workers' choices (printed)");
  app.add_option("--max-growth-mb", max_growth_mb, "Server memory growth allowed at the end");
  std::vector<std::string> only;
  std::vector<std::string> names;
  for (const auto& [name, run] : kCases) names.emplace_back(name);
  app.add_option("--case", only, "Only this case (repeat for more; default: every case)")
      ->check(CLI::IsMember(names));
  add_version_flag(app, "fluidcast-bench-soak");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return exit_for(app, e);
  }
  CaseList cases;
  for (const auto& entry : kCases) {
    if (only.empty() || std::find(only.begin(), only.end(), entry.first) != only.end()) {
      cases.push_back(entry);
    }
  }
  // Dual-stack on loopback: the workers come from 127.0.0.1 and the bystander from ::1, two
  // clients as two phones would be (the server shares its device between clients first).
  testing::ServerProcess server({"--listen", "::", "--max-sessions", "16",
                                 "--max-sessions-per-address", "16", "--resume-grace",
                                 std::to_string(kResumeGraceSeconds), "--hello-timeout", "2"});
  const std::string port = server.grpc_address().substr(server.grpc_address().rfind(':') + 1);
  const std::string address = "127.0.0.1:" + port, bystander_address = "[::1]:" + port;

  // The bystander alone first; then the baseline, once its session has ended.
  Figures f;
  std::tie(f.alone_fps, f.alone_frame_gpu_ms) =
      bystander_alone(bystander_address, f.bystander_error);
  std::this_thread::sleep_for(std::chrono::seconds(3));
  f.rss_kb[0] = server.resident_kb();
  f.descriptors[0] = server.open_descriptors();
  f.threads[0] = server.threads();
  f.thread_names[0] = server.thread_names();

  std::atomic<bool> stop{false};
  std::string bystander_error;
  std::thread bystander(
      [&] { f.during = bystander_windows(bystander_address, stop, bystander_error); });
  Tally tally;
  const auto end = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                      std::chrono::duration<double>(seconds));
  std::vector<std::thread> workers;
  for (unsigned k = 0; k < clients; ++k) {
    workers.emplace_back([&, k] { worker(address, cases, seed + k, end, tally); });
  }
  while (Clock::now() < end) {
    f.rss_kb[1] = std::max(f.rss_kb[1], server.resident_kb());
    std::this_thread::sleep_for(std::chrono::seconds(1));
  }
  for (auto& w : workers) w.join();
  stop = true;
  bystander.join();
  // Every session ends (a goodbye at once, a drop after the grace); freed memory is returned.
  std::this_thread::sleep_for(std::chrono::seconds(kResumeGraceSeconds + 5));
  f.rss_kb[2] = server.resident_kb();
  f.descriptors[1] = server.open_descriptors();
  f.threads[1] = server.threads();
  f.thread_names[1] = server.thread_names();
  f.bystander_error += bystander_error;
  std::printf("## fluidcast-bench-soak: %u workers, %.0f s, seed %llu\n\n", clients, seconds,
              static_cast<unsigned long long>(seed));
  return report(f, tally, max_growth_mb) ? 0 : 1;
}

}  // namespace
}  // namespace fluidcast

int main(int argc, char** argv) { return fluidcast::run(argc, argv); }

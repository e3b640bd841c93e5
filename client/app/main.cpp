// fluidcast-client: a window on a server's fluid (or a local one), or --headless for scripts and
// measurements.
#include <cctype>
#include <cstdio>
#include <string_view>
#include <utility>

#include "fluidcast/command_line.h"
#include "fluidcast/sim/particles.h"
#include "handoff_stream.h"
#include "headless_client.h"
#include "stream_client.h"
#include "window_client.h"

namespace {

namespace client = fluidcast::client;

struct Flags {
  bool headless = false, local = false, adaptive = false, json = false, handoff = false,
       no_handoff = false;
  std::string server = "127.0.0.1:50051", scene, solver, renderer, token, join, script, save_frames,
              screenshot;
  std::uint32_t width = 0, height = 0, particles = 0, quality = 0, fps = 0;
  std::uint32_t max_local = client::WindowOptions{}.max_local_particles;
  double seconds = 0.0;
};

void add_flags(CLI::App& app, Flags& f) {
  app.option_defaults()->always_capture_default();
  app.add_flag("--headless", f.headless, "No window: play a script, report figures");
  app.add_flag("--local", f.local, "Simulate and render here, without a server");
  app.add_option("--server", f.server, "HOST:PORT of the server's gRPC");
  const std::string at_most =
      std::to_string(client::kMaxViewportWidth) + "×" + std::to_string(client::kMaxViewportHeight);
  app.add_option("--width", f.width,
                 "Headless: the frames' width, pixels (0: 320); a window: its width in screen "
                 "points (0: 960), its frames as wide as its pixels (within " +
                     at_most + ")")
      ->check(CLI::Range(0u, 16384u));
  app.add_option("--height", f.height,
                 "Headless: the frames' height, pixels (0: 240); a window: its height in screen "
                 "points (0: 540), its frames as tall as its pixels (within " +
                     at_most + ")")
      ->check(CLI::Range(0u, 16384u));
  app.add_option("--particles", f.particles, "Particles of a new session (0: the default)")
      ->check(CLI::Range(0u, fluidcast::sim::kMostParticles));
  app.add_option("--scene", f.scene, "Scene of a new session (server default when empty)");
  app.add_option("--solver", f.solver, "pbf or sph (server default when empty)");
  app.add_option("--renderer", f.renderer, "auto, ssfr, mc or points (local default: mc)");
  app.add_option("--quality", f.quality, "JPEG quality 1-100 (0: server default)")
      ->check(CLI::Range(0u, 100u));
  app.add_option("--fps", f.fps, "Highest frame rate wanted (0: server's rate)")
      ->check(CLI::Range(0u, 1000u));
  app.add_flag("--adaptive", f.adaptive, "Let the server lower quality and size to keep up");
  app.add_option("--token", f.token, "Token, when the server wants one")
      ->envname("FLUIDCAST_TOKEN");
  app.add_option("--join", f.join,
                 "Join a session instead of creating one: its view key (to watch) or control key "
                 "(to play); a client prints both at start");
  app.add_option("--max-local-particles", f.max_local,
                 "Most particles simulated here (local mode and handoff)")
      ->check(CLI::Range(1u, 1u << 20));
  auto* handoff_flag = app.add_flag(
      "--handoff", f.handoff, "Headless: continue locally when the server drops (a window does)");
  app.add_flag("--no-handoff", f.no_handoff,
               "Window: do not continue locally when the server drops")
      ->excludes(handoff_flag);
  app.add_option("--script", f.script, "Headless: gesture script (JSON; see gesture_script.h)");
  app.add_option("--seconds", f.seconds,
                 "How long to run: headless from its first stream (0: 5 s), a window from its "
                 "start (0: until closed); Ctrl-C ends a run early")
      ->check(fluidcast::finite_range(0.0, 86400.0));
  app.add_option("--save-frames", f.save_frames, "Headless: write every frame received as JPEG");
  app.add_flag("--json", f.json, "Headless: last line is one JSON object with the figures");
  app.add_option("--screenshot", f.screenshot, "Window: write its last frame as PNG on exit");
}

fluidcast::v1::Hello hello_from(const Flags& f) {
  fluidcast::v1::Hello hello;
  hello.set_token(f.token);
  hello.mutable_viewport()->set_width(f.width ? f.width : (f.headless ? 320 : 960));
  hello.mutable_viewport()->set_height(f.height ? f.height : (f.headless ? 240 : 540));
  hello.mutable_quality()->set_jpeg_quality(f.quality);
  hello.mutable_quality()->set_max_fps(f.fps);
  hello.mutable_quality()->set_renderer(f.renderer);
  hello.mutable_quality()->set_adaptive(f.adaptive);
  if (!f.join.empty()) {
    hello.set_join(f.join);
  } else {
    hello.mutable_create()->set_scene(f.scene);
    hello.mutable_create()->set_solver(f.solver);
    hello.mutable_create()->set_particles(f.particles);
  }
  return hello;
}

// The Hello's fields that flags set (hello_from): a refusal at the start names the flag too, for
// the person who typed it ("NewSession.particles (--particles): 5000000 particles are more...").
constexpr std::pair<std::string_view, std::string_view> kFlagOfField[] = {
    {"Hello.token", "--token"},
    {"Hello.join", "--join"},
    {"NewSession.scene", "--scene"},
    {"NewSession.solver", "--solver"},
    {"NewSession.particles", "--particles"},
    {"Quality.jpeg_quality", "--quality"},
    {"Quality.max_fps", "--fps"},
    {"Quality.renderer", "--renderer"}};

std::string with_flags(const std::string& refusal) {
  std::string said = refusal;
  for (const auto& [field, flag] : kFlagOfField) {
    const std::size_t at = said.find(field);
    if (at == std::string::npos) continue;
    const std::size_t after = at + field.size();
    const bool longer_name =  // Hello.join is not Hello.joined, nor Hello.join.key
        after < said.size() &&
        (std::isalnum(static_cast<unsigned char>(said[after])) || said[after] == '_' ||
         (said[after] == '.' && after + 1 < said.size() &&
          std::isalpha(static_cast<unsigned char>(said[after + 1]))));
    if (!longer_name) said.insert(after, " (" + std::string(flag) + ")");
  }
  return said;
}

int run_headless(const Flags& f, const fluidcast::v1::Hello& hello) {
  if (f.local) {
    std::fprintf(stderr, "fluidcast-client: --local needs the window (drop --headless)\n");
    return 2;
  }
  try {
    return client::run_headless({f.server, hello, f.script, f.save_frames,
                                 f.seconds > 0 ? f.seconds : 5.0, f.json, f.handoff, f.max_local});
  } catch (const client::Unreachable& e) {  // no answer at all is not a refusal
    std::fprintf(stderr, "fluidcast-client: %s (--server %s)\n", e.what(), f.server.c_str());
    return 1;
  } catch (const client::StreamError& e) {
    std::fprintf(stderr, "fluidcast-client: the server refused: %s\n",
                 with_flags(e.what()).c_str());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fluidcast-client: %s\n", e.what());
    return 2;
  }
}

int run_window(const Flags& f, const fluidcast::v1::Hello& hello) {
  client::WindowOptions window;
  window.server = f.server;
  window.local = f.local;
  window.max_local_particles = f.max_local;
  window.handoff = !f.no_handoff;
  window.hello = hello;
  window.width = static_cast<int>(hello.viewport().width());
  window.height = static_cast<int>(hello.viewport().height());
  window.seconds = f.seconds;
  window.screenshot = f.screenshot;
  window.with_flags = with_flags;
  return client::run_window(window);
}

}  // namespace

int main(int argc, char** argv) {
  Flags flags;
  CLI::App app{"fluidcast-client: watch and touch a fluidcast session, or simulate one here"};
  fluidcast::add_version_flag(app, "fluidcast-client");
  add_flags(app, flags);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return fluidcast::exit_for(app, e);
  }
  const fluidcast::v1::Hello hello = hello_from(flags);
  return flags.headless ? run_headless(flags, hello) : run_window(flags, hello);
}

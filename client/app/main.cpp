// fluidcast-client: a window on a server's fluid (or a local one), or --headless for scripts and
// measurements.
#include <cstdio>

#include "fluidcast/command_line.h"
#include "handoff_stream.h"
#include "headless_client.h"
#include "stream_client.h"
#include "window_client.h"

int main(int argc, char** argv) {
  namespace client = fluidcast::client;
  bool headless = false, local = false, adaptive = false, json = false, handoff = false,
       no_handoff = false;
  std::string server = "127.0.0.1:50051", scene, solver, renderer, token, join, script, save_frames,
              screenshot;
  std::uint32_t width = 0, height = 0, particles = 0, quality = 0, fps = 0;
  std::uint32_t max_local = client::WindowOptions{}.max_local_particles;
  double seconds = 0.0;
  CLI::App app{"fluidcast-client: watch and touch a fluidcast session, or simulate one here"};
  fluidcast::add_version_flag(app, "fluidcast-client");
  app.option_defaults()->always_capture_default();
  app.add_flag("--headless", headless, "No window: play a script, report figures");
  app.add_flag("--local", local, "Simulate and render here, without a server");
  app.add_option("--server", server, "HOST:PORT of the server's gRPC");
  app.add_option("--width", width, "Frame width, pixels (default 320 headless, 960 window)");
  app.add_option("--height", height, "Frame height, pixels (default 240 headless, 540 window)");
  app.add_option("--particles", particles, "Particles of a new session (0: the default)");
  app.add_option("--scene", scene, "Scene of a new session (server default when empty)");
  app.add_option("--solver", solver, "pbf or sph (server default when empty)");
  app.add_option("--renderer", renderer, "auto, ssfr, mc or points (local default: mc)");
  app.add_option("--quality", quality, "JPEG quality 1-100 (0: server default)");
  app.add_option("--fps", fps, "Highest frame rate wanted (0: server's rate)");
  app.add_flag("--adaptive", adaptive, "Let the server lower quality and size to keep up");
  app.add_option("--token", token, "Token, when the server wants one")->envname("FLUIDCAST_TOKEN");
  app.add_option("--join", join,
                 "Join a session instead of creating one: its view key (to watch) or control key "
                 "(to play); a client prints both at start");
  app.add_option("--max-local-particles", max_local,
                 "Most particles simulated here (local mode and handoff)")
      ->check(CLI::Range(1u, 1u << 20));
  auto* handoff_flag = app.add_flag(
      "--handoff", handoff, "Headless: continue locally when the server drops (a window does)");
  app.add_flag("--no-handoff", no_handoff, "Window: do not continue locally when the server drops")
      ->excludes(handoff_flag);
  app.add_option("--script", script, "Headless: gesture script (JSON; see gesture_script.h)");
  app.add_option("--seconds", seconds, "How long to run (0: headless 5 s, window until closed)")
      ->check(CLI::Range(0.0, 86400.0));
  app.add_option("--save-frames", save_frames, "Headless: write every frame received as JPEG");
  app.add_flag("--json", json, "Headless: last line is one JSON object with the figures");
  app.add_option("--screenshot", screenshot, "Window: write its last frame as PNG on exit");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return fluidcast::exit_for(app, e);
  }

  fluidcast::v1::Hello hello;
  hello.set_token(token);
  hello.mutable_viewport()->set_width(width ? width : (headless ? 320 : 960));
  hello.mutable_viewport()->set_height(height ? height : (headless ? 240 : 540));
  hello.mutable_quality()->set_jpeg_quality(quality);
  hello.mutable_quality()->set_max_fps(fps);
  hello.mutable_quality()->set_renderer(renderer);
  hello.mutable_quality()->set_adaptive(adaptive);
  if (!join.empty()) {
    hello.set_join(join);
  } else {
    hello.mutable_create()->set_scene(scene);
    hello.mutable_create()->set_solver(solver);
    hello.mutable_create()->set_particles(particles);
  }
  if (headless) {
    if (local) {
      std::fprintf(stderr, "fluidcast-client: --local needs the window (drop --headless)\n");
      return 2;
    }
    try {
      return client::run_headless({server, hello, script, save_frames, seconds > 0 ? seconds : 5.0,
                                   json, handoff, max_local});
    } catch (const client::Unreachable& e) {  // no answer at all is not a refusal
      std::fprintf(stderr, "fluidcast-client: %s (--server %s)\n", e.what(), server.c_str());
      return 1;
    } catch (const client::StreamError& e) {
      std::fprintf(stderr, "fluidcast-client: the server refused: %s\n", e.what());
      return 1;
    } catch (const std::exception& e) {
      std::fprintf(stderr, "fluidcast-client: %s\n", e.what());
      return 2;
    }
  }
  client::WindowOptions window;
  window.server = server;
  window.local = local;
  window.max_local_particles = max_local;
  window.handoff = !no_handoff;
  window.hello = hello;
  window.width = static_cast<int>(hello.viewport().width());
  window.height = static_cast<int>(hello.viewport().height());
  window.seconds = seconds;
  window.screenshot = screenshot;
  return client::run_window(window);
}

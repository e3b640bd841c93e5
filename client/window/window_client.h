// fluidcast-client with a window (SDL2): shows a server's stream, or a local simulation, scaled to
// the window; mouse and touch become pointer events, an accelerometer (where SDL finds one) tilts
// gravity, keys send commands. When the server drops, it carries on with the same fluid locally
// (if the session is small enough) and hands back when the server returns.
#pragma once

#include <cstdint>
#include <functional>
#include <string>

#include "fluidcast/v1/fluidcast.pb.h"

namespace fluidcast::client {

// Frames a window asks for are at most this many pixels along each side (its shape kept).
inline constexpr int kMaxViewportWidth = 1920, kMaxViewportHeight = 1080;

struct WindowOptions {
  std::string server;  // HOST:PORT; ignored with local
  bool local = false;  // simulate here only
  std::uint32_t max_local_particles = 8000;
  bool handoff = true;  // continue locally when the server drops
  v1::Hello hello;      // scene, solver, particles, quality; the viewport follows the window
  int width = 960, height = 540;
  double seconds = 0.0;    // 0: until the window is closed
  std::string screenshot;  // a PNG of the window's last frame, written on exit
  // A refusal of the Hello as its reader should see it (the flags that set its fields named).
  std::function<std::string(const std::string&)> with_flags = [](const std::string& said) {
    return said;
  };
};

// Returns the process's exit status: 1 when the fluid did not open or the stream ended (its
// reason said on stderr, and in the window until it is closed where the fluid did not open).
int run_window(const WindowOptions& options);

}  // namespace fluidcast::client

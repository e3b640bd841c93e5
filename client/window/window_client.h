// fluidcast-client with a window (SDL2): shows a server's stream, or a local simulation, scaled to
// the window; mouse and touch become pointer events, an accelerometer (where SDL finds one) tilts
// gravity, keys send commands. When the server drops, it carries on with the same fluid locally
// (if the session is small enough) and hands back when the server returns.
#pragma once

#include <cstdint>
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
};

// Returns the process's exit status; errors are said in the window's title and on stderr.
int run_window(const WindowOptions& options);

}  // namespace fluidcast::client

// fluidcast-client --headless: connects to a server, plays a gesture script (or a default drag),
// decodes every frame, and reports frames, fps, bitrate and touch-to-photon latency. With --json
// its last line is one JSON object. With handoff it carries the fluid on here when the server
// drops (as the window does) and reports the gap; without, the run ends with the stream. SIGINT
// (Ctrl-C) or SIGTERM ends it early: the figures so far, a goodbye, exit status 128 + signal.
#pragma once

#include <string>

#include "fluidcast/v1/fluidcast.pb.h"

namespace fluidcast::client {

struct HeadlessOptions {
  std::string server;
  v1::Hello hello;
  std::string script;       // a gesture script (gesture_script.h); empty: the default drag
  std::string save_frames;  // a folder for every frame received, as JPEG
  double seconds = 5.0;
  bool json = false;
  bool handoff = false;
  std::uint32_t max_local_particles = 8000;
};

int run_headless(const HeadlessOptions& options);

}  // namespace fluidcast::client

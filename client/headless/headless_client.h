// fluidcast-client --headless: connects to a server, plays a gesture script (or a default drag),
// decodes every frame, and reports frames, fps, bitrate and touch-to-photon latency. With --json
// its last line is one JSON object.
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
};

int run_headless(const HeadlessOptions& options);

}  // namespace fluidcast::client

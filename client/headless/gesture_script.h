// A scripted sequence of input for the headless client: JSON, times in seconds from the start.
//   {"events": [
//     {"t": 0.5, "pointer": {"id": 0, "phase": "down", "x": 0.3, "y": 0.5}},
//     {"t": 0.6, "pointer": {"id": 0, "phase": "move", "x": 0.4, "y": 0.5}},
//     {"t": 1.0, "pointer": {"id": 0, "phase": "up",   "x": 0.4, "y": 0.5}},
//     {"t": 1.5, "tilt": [3.0, -9.3, 0.0]},
//     {"t": 2.0, "command": "reset"}]}
// Without a script the client drags a finger to and fro across the middle of the frame.
#pragma once

#include <string>
#include <vector>

#include "fluidcast/v1/fluidcast.pb.h"

namespace fluidcast::client {

struct ScriptedEvent {
  double time = 0.0;  // s from the start
  v1::ClientMessage message;
};

// Throws std::runtime_error naming the event and what is wrong with it.
std::vector<ScriptedEvent> read_gesture_script(const std::string& path);
// The same from the script's text; `name` says where it came from in errors.
std::vector<ScriptedEvent> parse_gesture_script(const std::string& text, const std::string& name);
// A finger dragged to and fro across the middle for `seconds`, 30 moves a second.
std::vector<ScriptedEvent> default_gesture(double seconds);

}  // namespace fluidcast::client

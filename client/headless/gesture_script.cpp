#include "gesture_script.h"

#include <cmath>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <stdexcept>

namespace fluidcast::client {
namespace {

v1::PointerEvent::Phase parse_phase(const std::string& phase) {
  if (phase == "down") return v1::PointerEvent::DOWN;
  if (phase == "move") return v1::PointerEvent::MOVE;
  if (phase == "up") return v1::PointerEvent::UP;
  if (phase == "cancel") return v1::PointerEvent::CANCEL;
  throw std::runtime_error("phase '" + phase + "' is not down, move, up or cancel");
}

ScriptedEvent pointer_at(double time, v1::PointerEvent::Phase phase, float x, float y) {
  ScriptedEvent event{time, {}};
  v1::PointerEvent& pointer = *event.message.mutable_pointer();
  pointer.set_pointer_id(0);
  pointer.set_phase(phase);
  pointer.set_x(x);
  pointer.set_y(y);
  return event;
}

}  // namespace

std::vector<ScriptedEvent> read_gesture_script(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("--script " + path + ": cannot open it");
  const std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  return parse_gesture_script(text, "--script " + path);
}

std::vector<ScriptedEvent> parse_gesture_script(const std::string& text, const std::string& name) {
  nlohmann::json script;
  try {
    script = nlohmann::json::parse(text);
  } catch (const std::exception& e) {
    throw std::runtime_error(name + ": not JSON: " + e.what());
  }
  if (!script.is_object() || !script.contains("events") || !script["events"].is_array()) {
    throw std::runtime_error(name + ": needs an object with an array \"events\"");
  }
  std::vector<ScriptedEvent> events;
  int index = 0;
  for (const auto& entry : script["events"]) {
    try {
      ScriptedEvent event{entry.at("t").get<double>(), {}};
      if (entry.contains("pointer")) {
        const auto& p = entry["pointer"];
        v1::PointerEvent& pointer = *event.message.mutable_pointer();
        pointer.set_pointer_id(p.value("id", 0u));
        pointer.set_phase(parse_phase(p.at("phase").get<std::string>()));
        pointer.set_x(p.at("x").get<float>());
        pointer.set_y(p.at("y").get<float>());
      } else if (entry.contains("tilt")) {
        const auto& g = entry["tilt"];
        event.message.mutable_tilt()->set_x(g.at(0).get<float>());
        event.message.mutable_tilt()->set_y(g.at(1).get<float>());
        event.message.mutable_tilt()->set_z(g.at(2).get<float>());
      } else if (entry.contains("command")) {
        const std::string command = entry["command"].get<std::string>();
        if (command == "reset") {
          event.message.mutable_command()->set_reset(true);
        } else if (command == "pause" || command == "resume") {
          event.message.mutable_command()->set_pause(command == "pause");
        } else {
          throw std::runtime_error("command '" + command + "' is not reset, pause or resume");
        }
      } else {
        throw std::runtime_error("needs a pointer, tilt or command");
      }
      events.push_back(std::move(event));
    } catch (const std::exception& e) {
      throw std::runtime_error(name + ": event " + std::to_string(index) + ": " + e.what());
    }
    ++index;
  }
  return events;
}

std::vector<ScriptedEvent> default_gesture(double seconds) {
  std::vector<ScriptedEvent> events;
  constexpr double kMovesPerSecond = 30.0;
  const auto x_at = [](double t) { return float(0.5 + 0.3 * std::sin(2.0 * M_PI * 0.5 * t)); };
  events.push_back(pointer_at(0.2, v1::PointerEvent::DOWN, x_at(0.2), 0.6f));
  for (double t = 0.2 + 1.0 / kMovesPerSecond; t < seconds - 0.2; t += 1.0 / kMovesPerSecond) {
    events.push_back(pointer_at(t, v1::PointerEvent::MOVE, x_at(t), 0.6f));
  }
  const double lift = std::max(0.3, seconds - 0.2);
  events.push_back(pointer_at(lift, v1::PointerEvent::UP, x_at(lift), 0.6f));
  return events;
}

}  // namespace fluidcast::client

#include "validation.h"

#include <cmath>
#include <cstdio>
#include <string_view>

#include "fluidcast/render/camera.h"
#include "fluidcast/render/frame_renderer.h"
#include "fluidcast/sim/scene.h"
#include "fluidcast/sim/solver.h"
#include "input_rules.h"
#include "refusal.h"

namespace fluidcast::server {
namespace {

[[noreturn]] void refuse(RefusalCode code, const std::string& message) {
  throw Refusal(code, message);
}

std::string text(std::uint32_t value) { return std::to_string(value); }

// A declared bound as a person writes it: 0.1, 89, 1000.
std::string number(float value) {
  char out[32];
  std::snprintf(out, sizeof out, "%g", double(value));
  return out;
}

// Names, ids and tokens are short; a long one is refused before it is copied anywhere.
constexpr std::size_t kMaxStringBytes = 256;

void check_length(const std::string& value, const char* field) {
  if (value.size() > kMaxStringBytes) {
    refuse(RefusalCode::invalid_argument,
           std::string(field) + " is longer than " + std::to_string(kMaxStringBytes) + " bytes");
  }
}

bool finite(float value) { return std::isfinite(value); }

// The field of a message that changes the fluid every viewer shares (what only control may send),
// or null. Pointers are not among them: a view-only viewer's pointers move only its camera.
const char* fluid_change(const v1::ClientMessage& message) {
  if (message.has_tilt()) return "Tilt";
  if (!message.has_command()) return nullptr;
  switch (message.command().kind_case()) {
    case v1::Command::kReset:
      return "Command.reset";
    case v1::Command::kScene:
      return "Command.scene";
    case v1::Command::kSolver:
      return "Command.solver";
    case v1::Command::kParticles:
      return "Command.particles";
    case v1::Command::kPause:
      return "Command.pause";
    default:
      return nullptr;
  }
}

// A scene or solver name in `field` of a message; the error names that field.
template <typename Parse>
void validate_name(const std::string& name, const char* field, Parse parse) {
  check_length(name, field);
  if (name.empty()) return;
  try {
    parse(name);
  } catch (const sim::ParamError& e) {
    refuse(RefusalCode::invalid_argument, e.worded([field](std::string_view) { return field; }));
  }
}

void validate_particles(std::uint32_t particles, const ServerLimits& limits, const char* field) {
  if (particles > limits.max_particles) {
    refuse(RefusalCode::resource_exhausted, std::string(field) + ": " + text(particles) +
                                                " particles are more than this server's limit of " +
                                                text(limits.max_particles) + " per session");
  }
}

void validate_camera(const v1::Camera& camera) {
  if (!finite(camera.yaw_degrees()) || !finite(camera.pitch_degrees()) ||
      !finite(camera.distance()) || !finite(camera.field_of_view_degrees())) {
    refuse(RefusalCode::invalid_argument, "Camera: every value must be finite");
  }
  using render::OrbitCamera;
  if (std::abs(camera.pitch_degrees()) > OrbitCamera::kMaxPitchDegrees) {
    refuse(RefusalCode::invalid_argument, "Camera.pitch_degrees must lie within −" +
                                              number(OrbitCamera::kMaxPitchDegrees) + " to " +
                                              number(OrbitCamera::kMaxPitchDegrees));
  }
  if (!(camera.distance() > 0.0f) || camera.distance() > OrbitCamera::kMaxDistance) {
    refuse(RefusalCode::invalid_argument, "Camera.distance must be above 0 and at most " +
                                              number(OrbitCamera::kMaxDistance) + " m");
  }
  const float fov = camera.field_of_view_degrees();
  if (fov != 0.0f && (fov < OrbitCamera::kMinFieldOfView || fov > OrbitCamera::kMaxFieldOfView)) {
    refuse(RefusalCode::invalid_argument,
           "Camera.field_of_view_degrees must be 0 (keep) or within " +
               number(OrbitCamera::kMinFieldOfView) + " to " +
               number(OrbitCamera::kMaxFieldOfView));
  }
}

void validate_pointer(const v1::PointerEvent& pointer) {
  if (pointer.phase() == v1::PointerEvent::PHASE_UNSPECIFIED ||
      !v1::PointerEvent::Phase_IsValid(pointer.phase())) {
    refuse(RefusalCode::invalid_argument, "PointerEvent.phase must be DOWN, MOVE, UP or CANCEL");
  }
  if (pointer.pointer_id() >= kPointerIds) {
    refuse(RefusalCode::invalid_argument,
           "PointerEvent.pointer_id must be below " + text(kPointerIds));
  }
  if (!finite(pointer.x()) || !finite(pointer.y()) || pointer.x() < 0.0f || pointer.x() > 1.0f ||
      pointer.y() < 0.0f || pointer.y() > 1.0f) {
    refuse(RefusalCode::invalid_argument,
           "PointerEvent.x and .y are normalised to the frame: finite, 0 to 1");
  }
}

void validate_tilt(const v1::Tilt& tilt) {
  const float magnitude =
      std::sqrt(tilt.x() * tilt.x() + tilt.y() * tilt.y() + tilt.z() * tilt.z());
  if (!std::isfinite(magnitude) || magnitude < kMinTiltGravity || magnitude > kMaxTiltGravity) {
    refuse(RefusalCode::invalid_argument,
           "Tilt: the gravity vector must be finite with a magnitude of " +
               number(kMinTiltGravity) + " to " + number(kMaxTiltGravity) + " m/s²");
  }
}

// A state handed back (NewSession.state, Hello.resume.state; `field` names it): its names and its
// size (the session checks each particle against its tank when it loads it).
void validate_state(const v1::Snapshot& state, const ServerLimits& limits, const char* field) {
  validate_scene(state.scene(), (std::string(field) + ".scene").c_str());
  validate_solver(state.solver(), (std::string(field) + ".solver").c_str());
  if (state.positions_size() % 3 != 0 || state.velocities_size() != state.positions_size()) {
    refuse(RefusalCode::invalid_argument,
           std::string(field) + ": positions and velocities need three values per particle each");
  }
  const auto particles = static_cast<std::uint32_t>(state.positions_size() / 3);
  if (particles == 0) refuse(RefusalCode::invalid_argument, std::string(field) + " has no particles");
  if (particles > kMaxStateParticles) {
    refuse(RefusalCode::resource_exhausted,
           std::string(field) + ": " + text(particles) + " particles are more than the " +
               text(kMaxStateParticles) + " a stream carries (InputRules.max_state_particles)");
  }
  validate_particles(particles, limits, field);
  validate_snapshot_time(state.time(), (std::string(field) + ".time").c_str());
}

void validate_command(const v1::Command& command, const ServerLimits& limits) {
  switch (command.kind_case()) {
    case v1::Command::kReset:
    case v1::Command::kPause:
    case v1::Command::kResetView:
      return;
    case v1::Command::kScene:
      if (command.scene().empty()) refuse(RefusalCode::invalid_argument, "Command.scene is empty");
      return validate_scene(command.scene(), "Command.scene");
    case v1::Command::kSolver:
      if (command.solver().empty()) {
        refuse(RefusalCode::invalid_argument, "Command.solver is empty");
      }
      return validate_solver(command.solver(), "Command.solver");
    case v1::Command::kParticles:
      if (command.particles() == 0) {
        refuse(RefusalCode::invalid_argument, "Command.particles must be at least 1");
      }
      return validate_particles(command.particles(), limits, "Command.particles");
    case v1::Command::kQuality:
      return validate_quality(command.quality(), limits);
    case v1::Command::kViewport:
      return validate_viewport(command.viewport());
    case v1::Command::kCamera:
      return validate_camera(command.camera());
    case v1::Command::KIND_NOT_SET:
      break;
  }
  refuse(RefusalCode::invalid_argument, "Command: no command was set");
}

}  // namespace

void validate_scene(const std::string& scene, const char* field) {
  validate_name(scene, field, sim::parse_scene);
}

void validate_solver(const std::string& solver, const char* field) {
  validate_name(solver, field, sim::parse_solver);
}

void validate_key(const std::string& key, const char* field) {
  check_length(key, field);
  if (key.empty()) {
    refuse(RefusalCode::invalid_argument,
           std::string(field) + " is empty: give a key from Welcome.access");
  }
}

void validate_token(const std::string& given, const std::optional<std::string>& token,
                    const char* field) {
  check_length(given, field);
  if (token && given != *token) {
    refuse(RefusalCode::unauthenticated,
           given.empty() ? "this server needs a token: set " + std::string(field)
                         : std::string(field) + " is not this server's token");
  }
}

void validate_snapshot_time(double seconds, const char* field) {
  if (!(std::isfinite(seconds) && seconds >= 0.0 && seconds <= kMaxSnapshotSeconds)) {
    refuse(RefusalCode::invalid_argument, std::string(field) + " must be 0 to " +
                                              number(static_cast<float>(kMaxSnapshotSeconds)) +
                                              " seconds");
  }
}

void validate_viewport(const v1::Viewport& viewport) {
  // One beyond the server's limits is not refused: its frames are scaled down to them (Viewer).
  if (viewport.width() == 0 || viewport.height() == 0) {
    refuse(RefusalCode::invalid_argument, "Viewport: width and height must be at least 1 pixel");
  }
}

void validate_quality(const v1::Quality& quality, const ServerLimits& limits) {
  if (quality.jpeg_quality() > kMaxJpegQuality) {
    refuse(RefusalCode::invalid_argument,
           "Quality.jpeg_quality must be 0 (default) or 1 to " + text(kMaxJpegQuality));
  }
  if (quality.max_fps() > limits.max_fps) {  // a server limit, as the particle count is
    refuse(RefusalCode::resource_exhausted, "Quality.max_fps " + text(quality.max_fps()) +
                                                " is beyond this server's limit of " +
                                                text(limits.max_fps) + " (0: the server's rate)");
  }
  check_length(quality.renderer(), "Quality.renderer");
  if (!quality.renderer().empty()) {
    try {
      render::parse_renderer(quality.renderer());
    } catch (const std::exception& e) {
      refuse(RefusalCode::invalid_argument, std::string("Quality.renderer: ") + e.what());
    }
  }
}

void validate_hello(const v1::ClientMessage& message, const ServerLimits& limits,
                    const std::optional<std::string>& token) {
  if (!message.has_hello()) {
    refuse(RefusalCode::failed_precondition, "the first message of a stream must be a Hello");
  }
  const v1::Hello& hello = message.hello();
  validate_token(hello.token(), token, "Hello.token");
  if (!hello.has_viewport()) refuse(RefusalCode::invalid_argument, "Hello.viewport is missing");
  validate_viewport(hello.viewport());
  validate_quality(hello.quality(), limits);
  switch (hello.session_case()) {
    case v1::Hello::kCreate:
      validate_scene(hello.create().scene(), "NewSession.scene");
      validate_solver(hello.create().solver(), "NewSession.solver");
      validate_particles(hello.create().particles(), limits, "NewSession.particles");
      if (hello.create().has_state()) {
        validate_state(hello.create().state(), limits, "NewSession.state");
      }
      break;
    case v1::Hello::kJoin:
      validate_key(hello.join(), "Hello.join");
      break;
    case v1::Hello::kResume:
      validate_key(hello.resume().key(), "Hello.resume.key");
      if (!hello.resume().session_key().empty()) {
        validate_key(hello.resume().session_key(), "Hello.resume.session_key");
      }
      if (hello.resume().has_state()) {
        validate_state(hello.resume().state(), limits, "Hello.resume.state");
      }
      break;
    case v1::Hello::SESSION_NOT_SET:
      break;
  }
}

void validate_event(const v1::ClientMessage& message, const ServerLimits& limits, Access access) {
  if (const char* change = fluid_change(message); change && access != Access::control) {
    refuse(RefusalCode::permission_denied,
           std::string(change) +
               ": this viewer joined with the session's view key; tilting and commanding the "
               "fluid need its control key");
  }
  switch (message.kind_case()) {
    case v1::ClientMessage::kHello:
      refuse(RefusalCode::failed_precondition, "a stream takes one Hello, as its first message");
    case v1::ClientMessage::kPointer:
      return validate_pointer(message.pointer());
    case v1::ClientMessage::kTilt:
      return validate_tilt(message.tilt());
    case v1::ClientMessage::kCommand:
      return validate_command(message.command(), limits);
    case v1::ClientMessage::kStateRequest:
      return;
    case v1::ClientMessage::kAck:
      return;
    case v1::ClientMessage::KIND_NOT_SET:
      break;
  }
  refuse(RefusalCode::invalid_argument, "ClientMessage: no message kind was set");
}

void check_rate(const v1::ClientMessage& message, StreamRates& rates, const ServerLimits& limits) {
  const auto now = std::chrono::steady_clock::now();
  if (message.has_state_request()) {
    if (!rates.states.allow(now)) {
      refuse(RefusalCode::resource_exhausted,
             "more than " + text(kStateRequestsPerSecond) + " state requests per second");
    }
  } else if (message.has_ack()) {
    if (!rates.acks.allow(now)) {
      refuse(RefusalCode::resource_exhausted, "more than " +
                                                  text(kAcknowledgementsPerFrame * limits.max_fps) +
                                                  " acknowledgements per second");
    }
  } else if (!rates.input.allow(now)) {
    refuse(RefusalCode::resource_exhausted,
           "more than " + text(limits.max_input_events_per_second) + " input events per second");
  }
}

StreamRates::StreamRates(const ServerLimits& limits)
    : input(limits.max_input_events_per_second),
      acks(kAcknowledgementsPerFrame * limits.max_fps),
      states(kStateRequestsPerSecond) {}

InputRateLimit::InputRateLimit(std::uint32_t per_second)
    : per_second_(per_second), tokens_(per_second), last_(std::chrono::steady_clock::now()) {}

bool InputRateLimit::allow(std::chrono::steady_clock::time_point now) {
  const std::chrono::duration<double> elapsed = now - last_;
  last_ = now;
  tokens_ = std::min(per_second_, tokens_ + elapsed.count() * per_second_);
  if (tokens_ < 1.0) return false;
  tokens_ -= 1.0;
  return true;
}

}  // namespace fluidcast::server

// Session: a viewer's messages, queued from any thread and applied at the tick.
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <new>

#include "fluidcast/gpu/vk_check.h"
#include "fluidcast/sim/scene.h"
#include "input_rules.h"
#include "session.h"

namespace fluidcast::server {

void Session::post(std::uint32_t viewer, v1::ClientMessage message) {
  const auto received = Clock::now();
  std::lock_guard lock(inbox_mutex_);
  inbox_.push_back({viewer, std::move(message), received});
}

void Session::apply(Viewer& viewer, const v1::ClientMessage& message, Clock::time_point received) {
  viewer.note_input(message.event_id(), received);
  switch (message.kind_case()) {
    case v1::ClientMessage::kPointer:
      viewer.apply_pointer(message.pointer());
      last_input_ = received;
      break;
    case v1::ClientMessage::kTilt:
      apply_tilt(viewer, message.tilt(), received);
      break;
    case v1::ClientMessage::kStateRequest:
      answer_state_request(viewer);
      break;
    case v1::ClientMessage::kAck:
      viewer.acknowledge(message.ack().sequence(), received);
      if (const auto round_trip = viewer.flow().round_trip_ms())
        services_.metrics->round_trip_time.observe_ms(*round_trip);
      break;
    case v1::ClientMessage::kCommand:
      last_input_ = received;
      apply_command(viewer, message.command());
      break;
    default:
      break;
  }
}

void Session::apply_tilt(Viewer& viewer, const v1::Tilt& tilt, Clock::time_point received) {
  const glm::vec3 gravity = viewer.gravity_from_tilt(tilt);
  solver_->set_gravity(gravity);
  // A phone lying still sends the same tilt twenty times a second: only turning it counts.
  const float turned = glm::degrees(std::acos(std::clamp(
      glm::dot(glm::normalize(gravity), glm::normalize(last_active_tilt_)), -1.0f, 1.0f)));
  if (turned > kIdleTiltDegrees) {
    last_active_tilt_ = gravity;
    last_input_ = received;
  }
}

void Session::answer_state_request(Viewer& viewer) {
  // A session past what a stream carries has no answer, and the stream goes on: its count
  // (Welcome.state, ServerMessage.session) says so, and a request sent before its client heard
  // that another viewer made the session larger is no fault of that client's.
  if (solver_->particle_count() > kMaxStateParticles) return;
  auto answer = std::make_shared<v1::ServerMessage>();
  try {
    *answer->mutable_state() = snapshot();
  } catch (const gpu::VulkanError& e) {
    // No GPU memory to read it out (other sessions hold it, or --gpu-memory is met): no answer
    // this time, and the stream and the session go on; a later request may find the room.
    if (!e.out_of_memory()) throw;
    spdlog::warn("session {}: a state request went unanswered: {}", id_, e.what());
    return;
  } catch (const std::bad_alloc&) {  // nor memory here: likewise, not every viewer's end
    spdlog::warn("session {}: a state request went unanswered: no memory for it", id_);
    return;
  }
  viewer.sink().deliver(answer);
}

void Session::apply_command(Viewer& viewer, const v1::Command& command) {
  // A new scene, solver or count waits for the next rebuild; the newest of each wins, and its
  // asker is told if it cannot be met.
  const auto rebuild = [&](auto change, std::uint32_t WishAskers::*asker) {
    SessionSetup setup = setup_wanted_.value_or(setup_);
    change(setup);
    setup_wanted_ = setup;
    wish_askers_.*asker = viewer.id();
  };
  switch (command.kind_case()) {
    case v1::Command::kReset:
      if (command.reset()) reset_wanted_ = true;
      break;
    case v1::Command::kPause:
      if (paused_ != command.pause()) {
        paused_ = command.pause();
        tell_state();
      }
      break;
    case v1::Command::kScene:
      rebuild([&](SessionSetup& setup) { setup.scene = sim::parse_scene(command.scene()); },
              &WishAskers::scene);
      break;
    case v1::Command::kSolver:
      rebuild([&](SessionSetup& setup) { setup.solver = sim::parse_solver(command.solver()); },
              &WishAskers::solver);
      break;
    case v1::Command::kParticles:
      rebuild([&](SessionSetup& setup) { setup.particles = command.particles(); },
              &WishAskers::particles);
      break;
    case v1::Command::kQuality:
      viewer.apply_quality(command.quality());
      break;
    case v1::Command::kViewport:
      viewer.apply_viewport(command.viewport());
      break;
    case v1::Command::kCamera:
      viewer.apply_camera(command.camera());
      break;
    case v1::Command::kResetView:
      viewer.reset_view();
      break;
    case v1::Command::KIND_NOT_SET:
      break;
  }
}

}  // namespace fluidcast::server

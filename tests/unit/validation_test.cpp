// Every rule of the protocol that the transport adapter checks, with the code it answers.
#include "session/validation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "session/input_rules.h"
#include "session/refusal.h"

namespace fluidcast::server {
namespace {

RefusalCode code_of(const std::function<void()>& check) {
  try {
    check();
  } catch (const Refusal& refusal) {
    return refusal.code();
  }
  ADD_FAILURE() << "accepted";
  return RefusalCode::unavailable;
}

v1::ClientMessage hello() {
  v1::ClientMessage message;
  message.mutable_hello()->mutable_viewport()->set_width(320);
  message.mutable_hello()->mutable_viewport()->set_height(240);
  return message;
}

TEST(ValidationTest, AGoodHelloPassesAndEachBadOneGetsItsCode) {
  const ServerLimits limits;
  EXPECT_NO_THROW(validate_hello(hello(), limits, std::nullopt));
  const std::optional<std::string> token = "secret";
  EXPECT_EQ(code_of([&] { validate_hello(hello(), limits, token); }), RefusalCode::unauthenticated);
  auto with_token = hello();
  with_token.mutable_hello()->set_token("secret");
  EXPECT_NO_THROW(validate_hello(with_token, limits, token));

  v1::ClientMessage tilt;
  tilt.mutable_tilt()->set_y(-9.81f);
  EXPECT_EQ(code_of([&] { validate_hello(tilt, limits, std::nullopt); }),
            RefusalCode::failed_precondition);
  auto zero = hello();
  zero.mutable_hello()->mutable_viewport()->set_width(0);
  EXPECT_EQ(code_of([&] { validate_hello(zero, limits, std::nullopt); }),
            RefusalCode::invalid_argument);
  auto huge = hello();
  huge.mutable_hello()->mutable_viewport()->set_height(limits.max_height + 1);
  EXPECT_EQ(code_of([&] { validate_hello(huge, limits, std::nullopt); }),
            RefusalCode::resource_exhausted);
  auto many = hello();
  many.mutable_hello()->mutable_create()->set_particles(limits.max_particles + 1);
  EXPECT_EQ(code_of([&] { validate_hello(many, limits, std::nullopt); }),
            RefusalCode::resource_exhausted);
  auto scene = hello();
  scene.mutable_hello()->mutable_create()->set_scene("ocean");
  EXPECT_EQ(code_of([&] { validate_hello(scene, limits, std::nullopt); }),
            RefusalCode::invalid_argument);
  try {
    validate_hello(scene, limits, std::nullopt);
  } catch (const Refusal& refusal) {  // the field where the client wrote it, not a flag
    EXPECT_EQ(std::string(refusal.what()).rfind("NewSession.scene: unknown scene 'ocean'", 0), 0u)
        << refusal.what();
  }
  auto renderer = hello();
  renderer.mutable_hello()->mutable_quality()->set_renderer("raytrace");
  EXPECT_EQ(code_of([&] { validate_hello(renderer, limits, std::nullopt); }),
            RefusalCode::invalid_argument);
  auto long_join = hello();
  long_join.mutable_hello()->set_join(std::string(257, 'a'));
  EXPECT_EQ(code_of([&] { validate_hello(long_join, limits, std::nullopt); }),
            RefusalCode::invalid_argument);
  auto long_token = hello();
  long_token.mutable_hello()->set_token(std::string(100000, 't'));
  EXPECT_EQ(code_of([&] { validate_hello(long_token, limits, token); }),
            RefusalCode::invalid_argument);
  auto quality = hello();
  quality.mutable_hello()->mutable_quality()->set_jpeg_quality(101);
  EXPECT_EQ(code_of([&] { validate_hello(quality, limits, std::nullopt); }),
            RefusalCode::invalid_argument);
  auto fast = hello();  // a server limit, as the frame size is
  fast.mutable_hello()->mutable_quality()->set_max_fps(limits.max_fps + 1);
  EXPECT_EQ(code_of([&] { validate_hello(fast, limits, std::nullopt); }),
            RefusalCode::resource_exhausted);
}

TEST(ValidationTest, AViewOnlyViewerChangesNothingButItsOwnView) {
  const ServerLimits limits;
  auto command = [](auto set) {
    v1::ClientMessage message;
    set(*message.mutable_command());
    return message;
  };
  const std::vector<v1::ClientMessage> changes = {
      command([](v1::Command& c) { c.set_reset(true); }),
      command([](v1::Command& c) { c.set_pause(true); }),
      command([](v1::Command& c) { c.set_scene("pool"); }),
      command([](v1::Command& c) { c.set_solver("sph"); }),
      command([](v1::Command& c) { c.set_particles(1000); }),
      [] {
        v1::ClientMessage message;
        message.mutable_tilt()->set_y(-9.81f);
        return message;
      }()};
  for (const auto& change : changes) {
    EXPECT_NO_THROW(validate_event(change, limits, Access::control)) << change.DebugString();
    try {
      validate_event(change, limits, Access::view);
      ADD_FAILURE() << "a view-only viewer sent " << change.DebugString();
    } catch (const Refusal& refusal) {
      EXPECT_EQ(refusal.code(), RefusalCode::permission_denied);
      EXPECT_NE(std::string(refusal.what()).find("control key"), std::string::npos);
    }
  }
  const std::vector<v1::ClientMessage> own = {
      command([](v1::Command& c) {
        c.mutable_viewport()->set_width(100);
        c.mutable_viewport()->set_height(100);
      }),
      command([](v1::Command& c) { c.set_reset_view(true); }),
      command([](v1::Command& c) { c.mutable_quality()->set_jpeg_quality(50); }),
      [] {
        v1::ClientMessage message;
        message.mutable_pointer()->set_phase(v1::PointerEvent::DOWN);
        return message;
      }(),
      [] {
        v1::ClientMessage message;
        message.mutable_state_request();
        return message;
      }()};
  for (const auto& message : own) {
    EXPECT_NO_THROW(validate_event(message, limits, Access::view)) << message.DebugString();
  }
}

TEST(AccessTest, KeysAreRandomAndOpenOnlyTheirSession) {
  const SessionKeys one, two;
  EXPECT_EQ(one.view.size(), 32u);
  EXPECT_NE(one.view, one.control);
  EXPECT_NE(one.view, two.view);
  EXPECT_EQ(one.opens(one.view), Access::view);
  EXPECT_EQ(one.opens(one.control), Access::control);
  EXPECT_EQ(one.opens(two.control), std::nullopt);
  EXPECT_EQ(one.opens(""), std::nullopt);
  EXPECT_EQ(one.opens(one.control.substr(0, 31)), std::nullopt);
  std::string near = one.control;
  near.back() = near.back() == '0' ? '1' : '0';
  EXPECT_EQ(one.opens(near), std::nullopt);
}

TEST(ValidationTest, InputOutOfItsRangeIsRefused) {
  const ServerLimits limits;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  v1::ClientMessage message;
  EXPECT_EQ(code_of([&] { validate_event(message, limits, Access::control); }),
            RefusalCode::invalid_argument);
  EXPECT_EQ(code_of([&] { validate_event(hello(), limits, Access::control); }),
            RefusalCode::failed_precondition);

  auto& pointer = *message.mutable_pointer();
  pointer.set_phase(v1::PointerEvent::DOWN);
  pointer.set_x(0.5f);
  pointer.set_y(1.0f);
  EXPECT_NO_THROW(validate_event(message, limits, Access::control));
  for (float bad : {nan, -0.01f, 1.01f, std::numeric_limits<float>::infinity()}) {
    pointer.set_x(bad);
    EXPECT_EQ(code_of([&] { validate_event(message, limits, Access::control); }),
              RefusalCode::invalid_argument)
        << bad;
  }
  pointer.set_x(0.5f);
  pointer.set_pointer_id(16);
  EXPECT_EQ(code_of([&] { validate_event(message, limits, Access::control); }),
            RefusalCode::invalid_argument);
  pointer.set_pointer_id(0);
  for (int phase : {int(v1::PointerEvent::PHASE_UNSPECIFIED), 7, -1}) {  // proto3 keeps any value
    pointer.set_phase(static_cast<v1::PointerEvent::Phase>(phase));
    EXPECT_EQ(code_of([&] { validate_event(message, limits, Access::control); }),
              RefusalCode::invalid_argument)
        << "phase " << phase;
  }

  auto& tilt = *message.mutable_tilt();
  tilt.set_y(-9.81f);
  EXPECT_NO_THROW(validate_event(message, limits, Access::control));
  tilt.set_y(nan);
  EXPECT_EQ(code_of([&] { validate_event(message, limits, Access::control); }),
            RefusalCode::invalid_argument);
  tilt.set_y(1e6f);
  EXPECT_EQ(code_of([&] { validate_event(message, limits, Access::control); }),
            RefusalCode::invalid_argument);
  tilt.set_y(0.0f);
  EXPECT_EQ(code_of([&] { validate_event(message, limits, Access::control); }),
            RefusalCode::invalid_argument);

  auto& camera = *message.mutable_command()->mutable_camera();
  camera.set_distance(2.0f);
  EXPECT_NO_THROW(validate_event(message, limits, Access::control));
  camera.set_pitch_degrees(95.0f);
  EXPECT_EQ(code_of([&] { validate_event(message, limits, Access::control); }),
            RefusalCode::invalid_argument);
  camera.set_pitch_degrees(0.0f);
  camera.set_distance(nan);
  EXPECT_EQ(code_of([&] { validate_event(message, limits, Access::control); }),
            RefusalCode::invalid_argument);
  message.mutable_command()->set_particles(limits.max_particles + 1);
  EXPECT_EQ(code_of([&] { validate_event(message, limits, Access::control); }),
            RefusalCode::resource_exhausted);
  message.mutable_command()->set_particles(0);
  EXPECT_EQ(code_of([&] { validate_event(message, limits, Access::control); }),
            RefusalCode::invalid_argument);
}

// What InputRules tells clients is exactly what validation enforces: each bound accepted, the
// step beyond it refused, and every advertised name accepted.
TEST(ValidationTest, TheAdvertisedRulesAreTheEnforcedOnes) {
  const ServerLimits limits;
  const v1::InputRules rules = input_rules(true);
  const auto pointer = [](std::uint32_t id) {
    v1::ClientMessage message;
    message.mutable_pointer()->set_pointer_id(id);
    message.mutable_pointer()->set_phase(v1::PointerEvent::DOWN);
    return message;
  };
  EXPECT_NO_THROW(validate_event(pointer(rules.pointer_ids() - 1), limits, Access::control));
  EXPECT_EQ(code_of([&] { validate_event(pointer(rules.pointer_ids()), limits, Access::control); }),
            RefusalCode::invalid_argument);
  const auto tilt = [](double magnitude) {
    v1::ClientMessage message;
    message.mutable_tilt()->set_y(static_cast<float>(-magnitude));
    return message;
  };
  EXPECT_NO_THROW(validate_event(tilt(rules.tilt_gravity().min()), limits, Access::control));
  EXPECT_NO_THROW(validate_event(tilt(rules.tilt_gravity().max()), limits, Access::control));
  EXPECT_EQ(code_of([&] {
              validate_event(tilt(rules.tilt_gravity().max() * 1.01), limits, Access::control);
            }),
            RefusalCode::invalid_argument);
  EXPECT_EQ(code_of([&] {
              validate_event(tilt(rules.tilt_gravity().min() * 0.5), limits, Access::control);
            }),
            RefusalCode::invalid_argument);
  const auto camera = [](double pitch, double distance, double fov) {
    v1::ClientMessage message;
    v1::Camera& c = *message.mutable_command()->mutable_camera();
    c.set_pitch_degrees(static_cast<float>(pitch));
    c.set_distance(static_cast<float>(distance));
    c.set_field_of_view_degrees(static_cast<float>(fov));
    return message;
  };
  const v1::Range& pitch = rules.camera_pitch_degrees();
  const v1::Range& distance = rules.camera_distance();
  const v1::Range& fov = rules.camera_field_of_view_degrees();
  EXPECT_NO_THROW(
      validate_event(camera(pitch.min(), distance.max(), fov.min()), limits, Access::control));
  EXPECT_NO_THROW(
      validate_event(camera(pitch.max(), distance.max(), fov.max()), limits, Access::control));
  EXPECT_EQ(
      code_of([&] { validate_event(camera(pitch.max() + 1, 1, 45), limits, Access::control); }),
      RefusalCode::invalid_argument);
  EXPECT_EQ(code_of([&] {
              validate_event(camera(0, distance.max() * 1.01, 45), limits, Access::control);
            }),
            RefusalCode::invalid_argument);
  EXPECT_EQ(
      code_of([&] { validate_event(camera(0, distance.min(), 45), limits, Access::control); }),
      RefusalCode::invalid_argument);
  EXPECT_EQ(code_of([&] { validate_event(camera(0, 1, fov.max() + 1), limits, Access::control); }),
            RefusalCode::invalid_argument);
  v1::ClientMessage quality;
  quality.mutable_command()->mutable_quality()->set_jpeg_quality(rules.max_jpeg_quality());
  EXPECT_NO_THROW(validate_event(quality, limits, Access::control));
  quality.mutable_command()->mutable_quality()->set_jpeg_quality(rules.max_jpeg_quality() + 1);
  EXPECT_EQ(code_of([&] { validate_event(quality, limits, Access::control); }),
            RefusalCode::invalid_argument);
  for (const std::string& name : rules.scenes()) {
    v1::ClientMessage message;
    message.mutable_command()->set_scene(name);
    EXPECT_NO_THROW(validate_event(message, limits, Access::control)) << name;
  }
  for (const std::string& name : rules.solvers()) {
    v1::ClientMessage message;
    message.mutable_command()->set_solver(name);
    EXPECT_NO_THROW(validate_event(message, limits, Access::control)) << name;
  }
  for (const std::string& name : rules.renderers()) {
    v1::ClientMessage message;
    message.mutable_command()->mutable_quality()->set_renderer(name);
    EXPECT_NO_THROW(validate_event(message, limits, Access::control)) << name;
  }
  EXPECT_EQ(input_rules(false).renderers_size(), 3);  // points, ssfr and auto
  const auto with_state_at = [](double seconds) {
    v1::ClientMessage message = hello();
    v1::Snapshot& state = *message.mutable_hello()->mutable_create()->mutable_state();
    for (int axis = 0; axis < 3; ++axis) {
      state.add_positions(0.1f);
      state.add_velocities(0.0f);
    }
    state.set_time(seconds);
    return message;
  };
  const v1::Range& seconds = rules.snapshot_seconds();
  EXPECT_NO_THROW(validate_hello(with_state_at(seconds.min()), limits, std::nullopt));
  EXPECT_NO_THROW(validate_hello(with_state_at(seconds.max()), limits, std::nullopt));
  for (double bad : {seconds.max() * 1.01, seconds.min() - 1.0, 1e300}) {
    EXPECT_EQ(code_of([&] { validate_hello(with_state_at(bad), limits, std::nullopt); }),
              RefusalCode::invalid_argument)
        << bad;
  }
}

TEST(ValidationTest, TheRateLimitAllowsASecondsBurstThenTheRate) {
  InputRateLimit limit(10);
  auto now = std::chrono::steady_clock::now();
  int allowed = 0;
  for (int k = 0; k < 30; ++k) allowed += limit.allow(now) ? 1 : 0;
  EXPECT_LE(allowed, 10);
  EXPECT_GE(allowed, 9);
  now += std::chrono::milliseconds(500);
  allowed = 0;
  for (int k = 0; k < 30; ++k) allowed += limit.allow(now) ? 1 : 0;
  EXPECT_EQ(allowed, 5);
}

}  // namespace
}  // namespace fluidcast::server

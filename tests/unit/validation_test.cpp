// Every rule of the protocol that the transport adapter checks, with the code it answers.
#include "session/validation.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <limits>
#include <set>

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

// What a refusal says, for the field it names; "accepted" when there was none.
std::string refusal_text(const std::function<void()>& check) {
  try {
    check();
  } catch (const Refusal& refusal) {
    return refusal.what();
  }
  return "accepted";
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
  auto many = hello();
  many.mutable_hello()->mutable_create()->set_particles(limits.max_particles + 1);
  EXPECT_EQ(code_of([&] { validate_hello(many, limits, std::nullopt); }),
            RefusalCode::resource_exhausted);
  auto scene = hello();
  scene.mutable_hello()->mutable_create()->set_scene("ocean");
  EXPECT_EQ(code_of([&] { validate_hello(scene, limits, std::nullopt); }),
            RefusalCode::invalid_argument);
  // The field where the client wrote it, not a flag.
  const std::string ocean = refusal_text([&] { validate_hello(scene, limits, std::nullopt); });
  EXPECT_TRUE(ocean.starts_with("NewSession.scene: unknown scene 'ocean'")) << ocean;
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
  for (const std::size_t at : {std::size_t{0}, one.control.size() / 2, one.control.size() - 1}) {
    std::string near = one.control;  // one character off, wherever it is
    near[at] = near[at] == '0' ? '1' : '0';
    EXPECT_EQ(one.opens(near), std::nullopt) << at;
  }
}

// A key's 32 characters are hexadecimal digits, every one of the sixteen in either half of a
// byte, and every character varies from key to key: 128 random bits, none lost in the spelling.
// (A digit missing from 3200 draws by chance: under 10⁻⁸⁸; a position alike in 200 keys: 10⁻²³⁹.)
TEST(AccessTest, KeysSpellAllOfTheirBits) {
  std::array<std::set<char>, 2> digits;  // in the high and the low half of each byte
  std::array<std::set<char>, 32> at_position;
  for (int k = 0; k < 200; ++k) {
    const std::string key = new_key();
    ASSERT_EQ(key.size(), 32u);
    for (std::size_t c = 0; c < key.size(); ++c) {
      digits[c % 2].insert(key[c]);
      at_position[c].insert(key[c]);
    }
  }
  for (std::size_t c = 0; c < at_position.size(); ++c) {
    EXPECT_GE(at_position[c].size(), 2u) << "character " << c << " is always the same";
  }
  const std::set<char> hexadecimal{'0', '1', '2', '3', '4', '5', '6', '7',
                                   '8', '9', 'a', 'b', 'c', 'd', 'e', 'f'};
  EXPECT_EQ(digits[0], hexadecimal);
  EXPECT_EQ(digits[1], hexadecimal);
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

// Each bound of the protocol is inclusive: the value at it passes (a string's length, the
// server's particles, frame size and rate, the pointer's corners), and for a string's length, the
// frame's width and the pointer the next one is refused, the first two naming the field as the
// message spells it (the others' next values are refused in the tests above).
TEST(ValidationTest, EveryBoundPassesAtItsEdgeAndNotBeyond) {
  const ServerLimits limits;
  // Strings: 256 bytes at most.
  auto join = hello();
  join.mutable_hello()->set_join(std::string(256, 'k'));
  EXPECT_NO_THROW(validate_hello(join, limits, std::nullopt));
  join.mutable_hello()->set_join(std::string(257, 'k'));
  const std::string long_join = refusal_text([&] { validate_hello(join, limits, std::nullopt); });
  EXPECT_TRUE(long_join.starts_with("Hello.join")) << long_join;
  // The server's limits: its own figure is allowed.
  auto create = hello();
  create.mutable_hello()->mutable_create()->set_particles(limits.max_particles);
  create.mutable_hello()->mutable_viewport()->set_width(limits.max_width);
  create.mutable_hello()->mutable_viewport()->set_height(limits.max_height);
  create.mutable_hello()->mutable_quality()->set_max_fps(limits.max_fps);
  EXPECT_NO_THROW(validate_hello(create, limits, std::nullopt));
  // A viewport beyond them too: its frames are scaled down to them (the viewer's).
  create.mutable_hello()->mutable_viewport()->set_width(limits.max_width + 1);
  EXPECT_NO_THROW(validate_hello(create, limits, std::nullopt));
  v1::ClientMessage particles;
  particles.mutable_command()->set_particles(limits.max_particles);
  EXPECT_NO_THROW(validate_event(particles, limits, Access::control));
  particles.mutable_command()->set_particles(1);
  EXPECT_NO_THROW(validate_event(particles, limits, Access::control));
  // The pointer's corners of the frame.
  v1::ClientMessage pointer;
  pointer.mutable_pointer()->set_phase(v1::PointerEvent::MOVE);
  for (const auto& [x, y] : {std::pair{0.0f, 0.0f}, std::pair{1.0f, 1.0f}, std::pair{1.0f, 0.0f}}) {
    pointer.mutable_pointer()->set_x(x);
    pointer.mutable_pointer()->set_y(y);
    EXPECT_NO_THROW(validate_event(pointer, limits, Access::control)) << x << ", " << y;
  }
  pointer.mutable_pointer()->set_y(-0.01f);
  const std::string off_frame =
      refusal_text([&] { validate_event(pointer, limits, Access::control); });
  EXPECT_TRUE(off_frame.starts_with("PointerEvent.x and .y")) << off_frame;
}

// A value that is not a number is refused in the camera's angles, the tilt and the pointer (its
// distance and the pointer's x above), not let through by a comparison that NaN fails.
TEST(ValidationTest, NoFieldTakesANonFiniteNumber) {
  const ServerLimits limits;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float infinity = std::numeric_limits<float>::infinity();
  for (const float bad : {nan, infinity}) {
    for (int field = 0; field < 3; ++field) {
      v1::ClientMessage message;
      v1::Camera& camera = *message.mutable_command()->mutable_camera();
      camera.set_distance(2.0f);
      camera.set_field_of_view_degrees(45.0f);
      if (field == 0) camera.set_pitch_degrees(bad);
      if (field == 1) camera.set_yaw_degrees(bad);
      if (field == 2) camera.set_field_of_view_degrees(bad);
      EXPECT_EQ(code_of([&] { validate_event(message, limits, Access::control); }),
                RefusalCode::invalid_argument)
          << "camera field " << field << " = " << bad;
    }
    v1::ClientMessage tilt;
    tilt.mutable_tilt()->set_y(-9.81f);
    tilt.mutable_tilt()->set_x(bad);
    EXPECT_EQ(code_of([&] { validate_event(tilt, limits, Access::control); }),
              RefusalCode::invalid_argument)
        << bad;
    v1::ClientMessage pointer;
    pointer.mutable_pointer()->set_phase(v1::PointerEvent::DOWN);
    pointer.mutable_pointer()->set_y(bad);
    EXPECT_EQ(code_of([&] { validate_event(pointer, limits, Access::control); }),
              RefusalCode::invalid_argument)
        << bad;
  }
}

// What a Hello must carry, and what a Command must not leave out.
TEST(ValidationTest, AMessageMissingWhatItNeedsIsRefused) {
  const ServerLimits limits;
  v1::ClientMessage no_viewport;
  no_viewport.mutable_hello();
  EXPECT_EQ(code_of([&] { validate_hello(no_viewport, limits, std::nullopt); }),
            RefusalCode::invalid_argument);
  // Not a viewport of 0 × 0 pixels, which it did not send.
  EXPECT_EQ(refusal_text([&] { validate_hello(no_viewport, limits, std::nullopt); }),
            "Hello.viewport is missing");
  auto flat = hello();
  flat.mutable_hello()->mutable_viewport()->set_height(0);
  EXPECT_EQ(code_of([&] { validate_hello(flat, limits, std::nullopt); }),
            RefusalCode::invalid_argument);
  auto join = hello();
  join.mutable_hello()->set_join("");
  EXPECT_EQ(code_of([&] { validate_hello(join, limits, std::nullopt); }),
            RefusalCode::invalid_argument);
  auto resume = hello();
  resume.mutable_hello()->mutable_resume()->set_key("");
  EXPECT_EQ(code_of([&] { validate_hello(resume, limits, std::nullopt); }),
            RefusalCode::invalid_argument);
  // The session's key beside a resume is optional, but not overlong.
  resume.mutable_hello()->mutable_resume()->set_key(std::string(32, 'a'));
  EXPECT_NO_THROW(validate_hello(resume, limits, std::nullopt));
  resume.mutable_hello()->mutable_resume()->set_session_key(std::string(300, 'a'));
  EXPECT_EQ(refusal_text([&] { validate_hello(resume, limits, std::nullopt); }),
            "Hello.resume.session_key is longer than 256 bytes");
  v1::ClientMessage scene;
  scene.mutable_command()->set_scene("");
  EXPECT_EQ(code_of([&] { validate_event(scene, limits, Access::control); }),
            RefusalCode::invalid_argument);
  v1::ClientMessage solver;
  solver.mutable_command()->set_solver("");
  EXPECT_EQ(code_of([&] { validate_event(solver, limits, Access::control); }),
            RefusalCode::invalid_argument);
  v1::ClientMessage nothing;
  nothing.mutable_command();
  EXPECT_EQ(code_of([&] { validate_event(nothing, limits, Access::control); }),
            RefusalCode::invalid_argument);
}

// A state handed back to a new session: whole particles, as many velocities as positions, at least
// one particle, no more than a stream carries or the server holds, and names it knows.
TEST(ValidationTest, AStateHandedBackIsCheckedWhole) {
  ServerLimits limits;
  const auto with_state = [](int particles, int velocities) {
    v1::ClientMessage message = hello();
    v1::Snapshot& state = *message.mutable_hello()->mutable_create()->mutable_state();
    for (int k = 0; k < 3 * particles; ++k) state.add_positions(0.1f);
    for (int k = 0; k < velocities; ++k) state.add_velocities(0.0f);
    return message;
  };
  EXPECT_NO_THROW(validate_hello(with_state(2, 6), limits, std::nullopt));
  EXPECT_EQ(code_of([&] { validate_hello(with_state(2, 5), limits, std::nullopt); }),
            RefusalCode::invalid_argument);
  auto partial = with_state(2, 7);
  partial.mutable_hello()->mutable_create()->mutable_state()->add_positions(0.1f);
  EXPECT_EQ(code_of([&] { validate_hello(partial, limits, std::nullopt); }),
            RefusalCode::invalid_argument);
  EXPECT_EQ(code_of([&] { validate_hello(with_state(0, 0), limits, std::nullopt); }),
            RefusalCode::invalid_argument);
  const int most = static_cast<int>(kMaxStateParticles);
  EXPECT_NO_THROW(validate_hello(with_state(most, 3 * most), limits, std::nullopt));
  EXPECT_EQ(
      code_of([&] { validate_hello(with_state(most + 1, 3 * most + 3), limits, std::nullopt); }),
      RefusalCode::resource_exhausted);
  limits.max_particles = 1;
  EXPECT_EQ(code_of([&] { validate_hello(with_state(2, 6), limits, std::nullopt); }),
            RefusalCode::resource_exhausted);
  limits = ServerLimits{};
  auto named = with_state(1, 3);
  named.mutable_hello()->mutable_create()->mutable_state()->set_scene("ocean");
  const std::string unknown = refusal_text([&] { validate_hello(named, limits, std::nullopt); });
  EXPECT_TRUE(unknown.starts_with("NewSession.state.scene")) << unknown;
}

// A stream's three budgets are apart: state requests spent do not stop its input, and input spent
// does not stop its acknowledgements.
TEST(ValidationTest, EachKindOfMessageSpendsItsOwnRate) {
  ServerLimits limits;
  limits.max_input_events_per_second = 5;
  limits.max_fps = 1;  // kAcknowledgementsPerFrame a frame: 4 a second, a quarter second a token
  StreamRates rates(limits);
  v1::ClientMessage state;
  state.mutable_state_request();
  v1::ClientMessage ack;
  ack.mutable_ack();
  v1::ClientMessage input;
  input.mutable_pointer()->set_phase(v1::PointerEvent::MOVE);
  for (std::uint32_t k = 0; k < kStateRequestsPerSecond; ++k) check_rate(state, rates, limits);
  EXPECT_EQ(code_of([&] { check_rate(state, rates, limits); }), RefusalCode::resource_exhausted);
  for (std::uint32_t k = 0; k < limits.max_input_events_per_second; ++k) {
    check_rate(input, rates, limits);
  }
  EXPECT_EQ(code_of([&] { check_rate(input, rates, limits); }), RefusalCode::resource_exhausted);
  for (std::uint32_t k = 0; k < kAcknowledgementsPerFrame * limits.max_fps; ++k) {
    check_rate(ack, rates, limits);
  }
  EXPECT_EQ(code_of([&] { check_rate(ack, rates, limits); }), RefusalCode::resource_exhausted);
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

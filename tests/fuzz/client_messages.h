// A client's messages read from any bytes, for session_fuzz, which plays clients: Hellos and
// events with every field mostly valid and now and then at, just past or far past its limit, or
// not a number; snapshots handed back as given or with one value broken.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "fluidcast/render/frame_renderer.h"
#include "fluidcast/sim/scene.h"
#include "fluidcast/sim/solver.h"
#include "fuzz_bytes.h"
#include "session/input_rules.h"
#include "session/server_limits.h"

namespace fluidcast::fuzzing {

using server::kMaxJpegQuality;
using server::kMaxSnapshotSeconds;
using server::kMaxTiltGravity;
using server::kMinTiltGravity;
using server::ServerLimits;

// A float for a field whose range is [low, high]: mostly inside it, now and then at or past its
// ends, or not a number. A zero byte (past the input's end) gives `low`.
inline float value_around(Bytes& in, float low, float high) {
  switch (in.byte() % 24) {
    case 0:
      return low;
    case 1:
      return high;
    case 2:
      return std::numeric_limits<float>::quiet_NaN();
    case 3:
      return std::numeric_limits<float>::infinity();
    case 4:
      return std::nextafter(high, 2.0f * high + 1.0f);
    case 5:
      return low - (high - low) * in.unit();
    default:
      return in.between(low, high);
  }
}

// A count or size for a field whose most is `most`: mostly within 1 to `most` (a zero byte, past
// the input's end, gives 1), now and then 0 (a count's default, a size refused), `most` or one
// past.
inline std::uint32_t count_around(Bytes& in, std::uint32_t most) {
  switch (in.byte() % 16) {
    case 13:
      return most;
    case 14:
      return 0;
    case 15:
      return most + 1;
    default:
      return 1 + static_cast<std::uint32_t>(in.unit() * static_cast<float>(most - 1));
  }
}

// Mostly one of `names`, now and then none (the default) or one that is none of them.
inline std::string name_from(Bytes& in, const std::vector<std::string_view>& names) {
  const std::size_t pick = in.byte() % (4 * names.size() + 2);
  if (pick < 4 * names.size()) return std::string(names[pick % names.size()]);
  return pick == 4 * names.size() ? std::string() : std::string("puddle");
}

inline void fill_viewport(Bytes& in, const ServerLimits& limits, v1::Viewport& viewport) {
  viewport.set_width(count_around(in, limits.max_width));
  viewport.set_height(count_around(in, limits.max_height));
}

inline void fill_quality(Bytes& in, const ServerLimits& limits, v1::Quality& quality) {
  quality.set_jpeg_quality(count_around(in, kMaxJpegQuality));
  quality.set_max_fps(count_around(in, limits.max_fps));
  quality.set_adaptive(in.byte() % 2);
  quality.set_renderer(name_from(in, render::renderer_names()));
}

// What the client knows of the server so far: keys, and the last state it was given (a snapshot,
// or a stream's answer to a StateRequest).
struct Known {
  std::vector<std::string> keys;  // view, control and resume keys from the Welcomes
  std::optional<v1::Snapshot> state;
  const std::string& key(Bytes& in) const {
    static const std::string unknown = "no-such-key";
    const std::size_t pick = in.byte() % (keys.size() + 1);
    return pick < keys.size() ? keys[pick] : unknown;
  }
};

// A snapshot as a client might hand it back: as the server gave it, or with a particle moved,
// sped up or made not a number, the gravity changed, or its time anywhere up to the limit and
// past it.
inline v1::Snapshot handed_back(Bytes& in, v1::Snapshot snapshot) {
  const int values = snapshot.positions_size();
  switch (in.byte() % 6) {
    case 0:
      if (values > 0) {
        const int value = in.byte() % values;
        snapshot.set_positions(value, value_around(in, -0.5f, 2.0f));
      }
      break;
    case 1:
      if (values > 0) {
        const int value = in.byte() % values;
        snapshot.set_velocities(value, value_around(in, -sim::kMaxSpeed, sim::kMaxSpeed));
      }
      break;
    case 2:
      snapshot.mutable_gravity()->set_y(-value_around(in, kMinTiltGravity, kMaxTiltGravity));
      break;
    case 3:
      snapshot.set_time(value_around(in, 0.0f, static_cast<float>(kMaxSnapshotSeconds)));
      break;
    default:
      break;
  }
  return snapshot;
}

inline v1::ClientMessage hello(Bytes& in, const ServerLimits& limits, const Known& known) {
  v1::ClientMessage message;
  v1::Hello& hello = *message.mutable_hello();
  fill_viewport(in, limits, *hello.mutable_viewport());
  if (in.byte() % 2) fill_quality(in, limits, *hello.mutable_quality());
  switch (in.byte() % 4) {
    case 1:
      hello.set_join(known.key(in));
      break;
    case 2: {
      v1::Resume& resume = *hello.mutable_resume();
      resume.set_key(known.key(in));
      if (in.byte() % 2) resume.set_session_key(known.key(in));
      if (known.state && in.byte() % 3 == 0) *resume.mutable_state() = handed_back(in, *known.state);
      break;
    }
    default: {
      v1::NewSession& create = *hello.mutable_create();
      create.set_scene(name_from(in, sim::scene_names()));
      create.set_solver(name_from(in, sim::solver_names()));
      create.set_particles(count_around(in, limits.max_particles));
      if (known.state && in.byte() % 3 == 0)
        *create.mutable_state() = handed_back(in, *known.state);
    }
  }
  return message;
}

// An event of a stream whose last frame was `last_frame`.
inline v1::ClientMessage event(Bytes& in, const ServerLimits& limits, const Known& known,
                               std::uint64_t last_frame) {
  v1::ClientMessage message;
  message.set_event_id(in.byte());
  switch (in.byte() % 16) {
    case 0:
    case 1:
    case 2:
    case 3:
    case 4:
    case 5: {
      v1::PointerEvent& pointer = *message.mutable_pointer();
      const std::uint32_t id = in.byte() % 24;  // mostly one of two fingers; now and then past
      pointer.set_pointer_id(id < 16 ? id % 2 : id - 6);
      const int phase = in.byte() % 18;  // mostly DOWN to CANCEL; now and then 0 or one past
      pointer.set_phase(
          static_cast<v1::PointerEvent::Phase>(phase < 16 ? 1 + phase % 4 : 5 * (phase - 16)));
      pointer.set_x(value_around(in, 0.0f, 1.0f));
      pointer.set_y(value_around(in, 0.0f, 1.0f));
      break;
    }
    case 6:
    case 7: {
      v1::Tilt& tilt = *message.mutable_tilt();
      const glm::vec3 direction = in.direction();
      const glm::vec3 gravity = direction * value_around(in, kMinTiltGravity, kMaxTiltGravity);
      tilt.set_x(gravity.x);
      tilt.set_y(gravity.y);
      tilt.set_z(gravity.z);
      break;
    }
    case 8:
    case 9:
    case 10:
    case 11: {
      v1::Command& command = *message.mutable_command();
      switch (in.byte() % 9) {
        case 0:
          command.set_reset(true);
          break;
        case 1:
          command.set_scene(name_from(in, sim::scene_names()));
          break;
        case 2:
          command.set_solver(name_from(in, sim::solver_names()));
          break;
        case 3:
          command.set_particles(count_around(in, limits.max_particles));
          break;
        case 4:
          fill_quality(in, limits, *command.mutable_quality());
          break;
        case 5:
          command.set_pause(in.byte() % 2);
          break;
        case 6:
          fill_viewport(in, limits, *command.mutable_viewport());
          break;
        case 7: {
          v1::Camera& camera = *command.mutable_camera();
          camera.set_yaw_degrees(value_around(in, -720.0f, 720.0f));
          camera.set_pitch_degrees(value_around(in, -89.0f, 89.0f));
          camera.set_distance(value_around(in, 0.0f, 1000.0f));
          camera.set_field_of_view_degrees(value_around(in, 1.0f, 170.0f));
          break;
        }
        default:
          command.set_reset_view(true);
      }
      break;
    }
    case 12:
    case 13:
      message.mutable_ack()->set_sequence(in.byte() % 4 ? last_frame : in.byte());
      message.set_event_id(0);
      break;
    case 14:
      message.mutable_state_request();
      break;
    default:
      *message.mutable_hello() = hello(in, limits, known).hello();
  }
  return message;
}

}  // namespace fluidcast::fuzzing

// Every input's range and vocabulary, declared once: validation refuses what lies outside them, and
// Welcome and ServerInfo send them (v1::InputRules) so clients build their menus and clamps from
// them. The camera's ranges are the camera's own (render::OrbitCamera), the names the simulation's
// and the renderer's.
#pragma once

#include <cstddef>
#include <cstdint>

#include "fluidcast/v1/fluidcast.pb.h"
#include "fluidcast/v1/wire_sizes.h"

namespace fluidcast::server {

// A tilt's gravity, m/s²: below the least, the phone is in free fall (or its sensor's first
// reading is zero); the most is about 20 g, more than a shaken phone reads.
inline constexpr float kMinTiltGravity = 0.1f;
inline constexpr float kMaxTiltGravity = 200.0f;
// Touches at once: PointerEvent.pointer_id lies below this.
inline constexpr std::uint32_t kPointerIds = 16;
inline constexpr std::uint32_t kMaxJpegQuality = 100;
// The largest session whose state a stream carries (StateRequest, NewSession.state), so that a
// WebSocket message stays small. Larger ones use GetSnapshot and PutSnapshot.
inline constexpr std::uint32_t kMaxStateParticles = 16384;
inline constexpr std::uint32_t kStateRequestsPerSecond = 4;
// The largest ClientMessage a stream takes, bytes: a Hello carrying the largest state, and room for
// the rest; every other message is well under 1 KiB.
inline constexpr std::size_t kMaxClientMessageBytes =
    v1::kSnapshotBytesPerParticle * kMaxStateParticles + 64 * 1024;
// A snapshot's simulated time, s: about 30 years, beyond any session's, and far within the range
// where a step still moves a double's clock.
inline constexpr double kMaxSnapshotSeconds = 1e9;

// The table as clients receive it; `mc_drawable`: the device draws Marching Cubes (else it is not
// offered).
v1::InputRules input_rules(bool mc_drawable);

}  // namespace fluidcast::server

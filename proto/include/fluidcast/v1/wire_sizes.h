// Sizes on the wire that follow from fluidcast.proto, for the limits and deadlines that both ends
// set from them.
#pragma once

#include <cstddef>

namespace fluidcast::v1 {

// A particle in a Snapshot (or a stream's state): three packed floats of its position and three of
// its velocity.
inline constexpr std::size_t kSnapshotBytesPerParticle = 6 * sizeof(float);

}  // namespace fluidcast::v1

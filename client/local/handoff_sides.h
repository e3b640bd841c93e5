// The two sides a client's fluid moves between: a server's Stream over gRPC, and a session
// simulated in this process.
#pragma once

#include <cstdint>
#include <string>

#include "handoff_stream.h"

namespace fluidcast::client {

// `server` is HOST:PORT; a local fluid holds at most `max_local_particles`.
HandoffSides handoff_sides(const std::string& server, std::uint32_t max_local_particles);

}  // namespace fluidcast::client

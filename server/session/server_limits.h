// What one server allows. Every limit has a flag and an environment variable (server/options.cpp)
// and is sent to clients in Welcome and ServerInfo.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>

namespace fluidcast::server {

// Turning a device by more than this counts as a viewer's input (ServerLimits::idle_timeout).
inline constexpr float kIdleTiltDegrees = 10.0f;

// Viewers of one session kept for a resume (within ServerLimits::resume_grace); beyond it, those
// who left earliest are forgotten.
inline constexpr std::size_t kMaxDepartedViewers = 64;

struct ServerLimits {
  std::uint32_t max_sessions = 8;
  // Sessions the clients of one address may hold at once (those waiting for a resume included),
  // so that no one client takes every slot. Default: half of max_sessions, rounded up.
  std::uint32_t max_sessions_per_address = 4;
  std::uint32_t max_particles = 1 << 20;  // per session
  // A session's particles when its client names no count: the server measures what its device
  // keeps in real time at start (default_size.h) unless the operator says.
  std::uint32_t default_particles = 20000;
  std::uint32_t max_width = 3840;
  std::uint32_t max_height = 2160;
  std::uint32_t target_fps = 60;  // sessions step and render at this rate (a GPU's)
  // Of each tick's period, the GPU time that all sessions' simulation may take together (the rest
  // is for rendering, read-back and headroom); beyond it the fluid runs in slow motion.
  double sim_share = 0.5;
  // Of each period, the GPU time all sessions may be granted together when a GPU solver's fluid
  // wants more than sim_share: what rendering does not ask for, up to this, goes to simulation
  // (equally by client, as the shares). The rest is headroom against the costs' estimates. A
  // lone 1M-particle viewer on an H200 left the device 45 % idle at sim_share alone, its fluid at
  // a tenth of real time. At or below sim_share: none. A CPU device's default is sim_share: its
  // time is the CPU's, which the encoders and the network need too.
  double busy_share = 0.8;
  std::uint32_t max_fps = 120;
  std::uint32_t max_viewers_per_session = 8;
  std::uint32_t max_input_events_per_second = 400;  // per stream; a flood ends the stream
  std::chrono::seconds resume_grace{30};            // a session without viewers lives this long
  // A session whose viewers neither touch, tilt (by more than kIdleTiltDegrees) nor command it
  // for this long ends their streams (DEADLINE_EXCEEDED) and frees the GPU; 0: never. A phone
  // left on a table should not hold a GPU's share forever.
  std::chrono::seconds idle_timeout{600};
  // A stream (gRPC or WebSocket) that sends no Hello this long after it opens is ended
  // (DEADLINE_EXCEEDED): an idle connection must not hold a descriptor forever.
  std::chrono::seconds hello_timeout{10};
  // HTTP and WebSocket connections open at once, in all and from one address; one over either is
  // closed as soon as it is accepted. The total is lowered to half the process's descriptors.
  // gRPC connections are held to the same number from one address (counted apart).
  std::uint32_t max_connections = 4096;
  std::uint32_t max_connections_per_address = 64;
};

}  // namespace fluidcast::server

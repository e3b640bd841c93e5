// fluidcast-server's flags; each also reads an environment variable (FLUIDCAST_…), so a container
// or a systemd unit can set them.
#pragma once

#include <CLI/CLI.hpp>
#include <optional>
#include <string>
#include <vector>

#include "log.h"
#include "session/server_limits.h"

namespace fluidcast::server {

enum class SolverBackend { automatic, gpu, cpu };

struct ServerOptions {
  std::string listen = "0.0.0.0";
  unsigned short grpc_port = 50051;
  unsigned short http_port = 8080;
  std::optional<std::uint32_t> device;
  bool list_devices = false;         // print them and exit, serving nothing
  std::uint32_t gpu_memory_mib = 0;  // the most GPU memory the server allocates; 0: no limit
  SolverBackend backend = SolverBackend::automatic;
  ServerLimits limits;  // as given, but for the two below
  // New sessions' particles, the tick rate and the busy share, where the operator gave them.
  std::optional<std::uint32_t> default_particles, target_fps;
  std::optional<double> busy_share;
  std::string tls_certificate, tls_key;  // PEM files; both or neither
  std::string token_file;                // a file whose first line is the token clients must send
  // Other sites' pages that may open /ws (scheme://host[:port]); the server's own always may.
  std::vector<std::string> allowed_origins;
  std::vector<std::string> server_names;  // --server-name: what browsers reach it by
  LogFormat log_format = LogFormat::text;
  // After SIGTERM, how long /healthz says 503 and the gRPC health service NOT_SERVING while
  // streams go on, before they end: time for a load balancer to send new clients elsewhere.
  unsigned drain_seconds = 0;
  std::string state_dir;  // what the server makes and keeps (default_state_folder)
  // The phone page's folder: index.html, app.js, style.css, manifest.webmanifest, fluidcast.proto
  // and vendor/protobuf.min.js (default: share/fluidcast/web beside the binary's bin/).
  std::string web_root;

  // The limits for the device: where the operator gave no tick rate, a CPU device (lavapipe,
  // which renders a 20 000-particle session at 1.5–4 frames/s with a second of latency) gets 30
  // frames/s, a GPU ServerLimits' default; where the operator gave no busy share, a CPU device
  // gets the simulation's share (no more for simulation), a GPU ServerLimits' default; where the
  // operator gave no default particle count, `fitting_particles`, what the device was measured to
  // keep in real time (default_size.h).
  ServerLimits limits_for(bool hardware, std::uint32_t fitting_particles) const;
};

// Exits the process with CLI11's message and status for --help or bad flags.
ServerOptions parse_server_options(int argc, char** argv);
// The same on `app`, without exiting: throws CLI::ParseError (CLI::CallForHelp and
// CLI::CallForVersion too, and CLI::Success once --list-settings has printed
// docs/server-settings.md: before the environment is read, whose bad values it would refuse)
// for the caller to report with exit_for(app, error).
ServerOptions read_server_options(CLI::App& app, int argc, const char* const* argv);

}  // namespace fluidcast::server

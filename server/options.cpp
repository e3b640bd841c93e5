#include "options.h"

#include <algorithm>
#include <cctype>
#include <string>

#include "fluidcast/command_line.h"
#include "fluidcast/gpu/memory.h"
#include "fluidcast/program_folder.h"

namespace fluidcast::server {

ServerOptions parse_server_options(int argc, char** argv) {
  CLI::App app{
      "fluidcast-server: simulates and renders fluids on a GPU, headless, and streams "
      "them as JPEG frames over gRPC (and the page's WebSocket)"};
  try {
    return read_server_options(app, argc, argv);
  } catch (const CLI::ParseError& e) {
    std::exit(exit_for(app, e));
  }
}

ServerOptions read_server_options(CLI::App& app, int argc, const char* const* argv) {
  ServerOptions o;
  ServerLimits& l = o.limits;
  add_version_flag(app, "fluidcast-server");
  app.option_defaults()->always_capture_default();
  app.add_option(
         "--listen", o.listen,
         "Address to listen on (0.0.0.0: every IPv4 interface; ::, every interface, IPv6 and IPv4)")
      ->envname("FLUIDCAST_LISTEN");
  app.add_option("--grpc-port", o.grpc_port, "gRPC port (0: any free port, printed at start)")
      ->envname("FLUIDCAST_GRPC_PORT");
  app.add_option("--http-port", o.http_port,
                 "HTTP port: /metrics, /healthz (0: any free port, printed at start)")
      ->envname("FLUIDCAST_HTTP_PORT");
  app.add_option("--device", o.device,
                 "Vulkan device index (default: the best device present; --list-devices)")
      ->envname("FLUIDCAST_DEVICE");
  app.add_flag("--list-devices", o.list_devices,
               "Print the Vulkan devices, their indices for --device and which is the default, "
               "and exit");
  constexpr auto kBlockMib = static_cast<std::uint32_t>(gpu::MemoryAllocator::kBlockSize >> 20);
  const std::string least_gpu_memory = "0 (no cap) or at least " + std::to_string(kBlockMib) +
                                       " MiB: GPU memory is taken in blocks "
                                       "of that";
  app.add_option("--gpu-memory", o.gpu_memory_mib,
                 "Most GPU memory the server allocates, MiB, " + least_gpu_memory +
                     "; servers sharing a GPU each keep to theirs. Past it, a session or frame "
                     "size that needs more is refused (RESOURCE_EXHAUSTED), the others go on")
      ->envname("FLUIDCAST_GPU_MEMORY")
      ->check(CLI::Range(0u, 16u << 20));
  std::string backend = "auto";
  app.add_option("--backend", backend,
                 "Where sessions simulate: gpu, cpu, or auto (gpu on a hardware device, cpu on "
                 "lavapipe, where the CPU solver is faster)")
      ->envname("FLUIDCAST_BACKEND")
      ->check(CLI::IsMember({"auto", "gpu", "cpu"}));
  app.add_option("--max-sessions", l.max_sessions, "Most sessions at once")
      ->envname("FLUIDCAST_MAX_SESSIONS")
      ->check(CLI::Range(1u, 1024u));
  std::optional<std::uint32_t> sessions_per_address;
  app.add_option("--max-sessions-per-address", sessions_per_address,
                 "Most sessions the clients of one address may hold at once, those waiting for a "
                 "resume included (default: half of --max-sessions, rounded up)")
      ->envname("FLUIDCAST_MAX_SESSIONS_PER_ADDRESS")
      ->check(CLI::Range(1u, 1024u));
  app.add_option("--max-particles", l.max_particles, "Most particles per session")
      ->envname("FLUIDCAST_MAX_PARTICLES")
      ->check(CLI::Range(1u, 16u << 20));
  app.add_option("--default-particles", o.default_particles,
                 "Particles of a session whose client names no count (default: the most that "
                 "this device keeps in real time, measured at start)")
      ->envname("FLUIDCAST_DEFAULT_PARTICLES")
      ->check(CLI::Range(1u, 16u << 20));
  app.add_option("--max-width", l.max_width,
                 "Widest frame drawn, pixels: a viewer asking for more gets frames scaled down, "
                 "its shape kept")
      ->envname("FLUIDCAST_MAX_WIDTH")
      ->check(CLI::Range(1u, 16384u));
  app.add_option("--max-height", l.max_height,
                 "Tallest frame drawn, pixels: a viewer asking for more gets frames scaled down, "
                 "its shape kept")
      ->envname("FLUIDCAST_MAX_HEIGHT")
      ->check(CLI::Range(1u, 16384u));
  app.add_option("--target-fps", o.target_fps,
                 "Ticks per second: sessions step and render (default: 60 on a GPU, 30 on a CPU "
                 "device)")
      ->envname("FLUIDCAST_TARGET_FPS")
      ->check(CLI::Range(1u, 1000u));
  app.add_option("--sim-share", l.sim_share,
                 "Of each tick's period, the GPU time all sessions' simulation may take together "
                 "whatever the frames need; beyond it (and --busy-share) fluids run in slow "
                 "motion, frames keep their rate")
      ->envname("FLUIDCAST_SIM_SHARE")
      ->check(finite_range(0.05, 0.95));
  app.add_option("--busy-share", o.busy_share,
                 "Of each tick's period, the GPU time all sessions may take together when a GPU "
                 "solver's fluid wants more than --sim-share: simulation gets what rendering "
                 "leaves up to it (default: 0.8 on a GPU; --sim-share, so none, on a CPU device)")
      ->envname("FLUIDCAST_BUSY_SHARE")
      ->check(finite_range(0.05, 0.95));
  app.add_option("--max-fps", l.max_fps, "Highest frame rate a viewer may ask for")
      ->envname("FLUIDCAST_MAX_FPS")
      ->check(CLI::Range(1u, 1000u));
  app.add_option("--max-viewers", l.max_viewers_per_session, "Most viewers per session")
      ->envname("FLUIDCAST_MAX_VIEWERS")
      ->check(CLI::Range(1u, 1024u));
  app.add_option("--max-input-rate", l.max_input_events_per_second,
                 "Input events per second a stream may send; beyond, RESOURCE_EXHAUSTED")
      ->envname("FLUIDCAST_MAX_INPUT_RATE")
      ->check(CLI::Range(1u, 100000u));
  unsigned grace = static_cast<unsigned>(l.resume_grace.count());
  app.add_option("--resume-grace", grace,
                 "Seconds a session without viewers lives on, for a client to resume it")
      ->envname("FLUIDCAST_RESUME_GRACE")
      ->check(CLI::Range(0u, 86400u));
  unsigned idle = static_cast<unsigned>(l.idle_timeout.count());
  app.add_option("--idle-timeout", idle,
                 "Seconds a session may go without any viewer's touch, tilt or command before its "
                 "streams end (0: never)")
      ->envname("FLUIDCAST_IDLE_TIMEOUT")
      ->check(CLI::Range(0u, 604800u));
  unsigned hello = static_cast<unsigned>(l.hello_timeout.count());
  app.add_option("--hello-timeout", hello,
                 "Seconds a new stream may take to send its Hello before it is ended")
      ->envname("FLUIDCAST_HELLO_TIMEOUT")
      ->check(CLI::Range(1u, 600u));
  app.add_option("--max-connections", l.max_connections,
                 "HTTP and WebSocket connections open at once (at most half the descriptors the "
                 "process may open)")
      ->envname("FLUIDCAST_MAX_CONNECTIONS")
      ->check(CLI::Range(1u, 1u << 20));
  app.add_option("--max-connections-per-address", l.max_connections_per_address,
                 "HTTP and WebSocket connections open at once from one address, and as many "
                 "gRPC connections")
      ->envname("FLUIDCAST_MAX_CONNECTIONS_PER_ADDRESS")
      ->check(CLI::Range(1u, 1u << 20));
  app.add_option("--tls-cert", o.tls_certificate,
                 "TLS certificate chain (PEM) for gRPC and the page's HTTPS (without it the page "
                 "gets a self-signed one, made in --state-dir, and gRPC is plaintext)")
      ->envname("FLUIDCAST_TLS_CERT")
      ->check(CLI::ExistingFile);
  app.add_option("--tls-key", o.tls_key, "TLS private key (PEM) for --tls-cert")
      ->envname("FLUIDCAST_TLS_KEY")
      ->check(CLI::ExistingFile);
  app.add_option("--drain", o.drain_seconds,
                 "Seconds between SIGTERM and the streams' end, while /healthz says 503 (a second "
                 "signal cuts it short)")
      ->envname("FLUIDCAST_DRAIN")
      ->check(CLI::Range(0u, 3600u));
  std::string log_format = "text";
  app.add_option("--log-format", log_format,
                 "Log lines on stdout as text (time, level, event) or json (an object a line)")
      ->envname("FLUIDCAST_LOG_FORMAT")
      ->check(CLI::IsMember({"text", "json"}));
  app.add_option("--state-dir", o.state_dir,
                 "Folder for what the server makes and keeps: the self-signed certificate "
                 "(default: $STATE_DIRECTORY, else $XDG_STATE_HOME/fluidcast, else "
                 "~/.local/state/fluidcast)")
      ->envname("FLUIDCAST_STATE_DIR");
  app.add_option("--allow-origin", o.allowed_origins,
                 "A page from another site that may open the WebSocket, as scheme://host[:port] "
                 "(repeat it, or separate by commas); the server's own page always may")
      ->envname("FLUIDCAST_ALLOW_ORIGIN")
      ->delimiter(',')
      ->check(CLI::Validator(
          [](std::string& origin) -> std::string {
            const bool web = origin.rfind("http://", 0) == 0 || origin.rfind("https://", 0) == 0;
            return web && origin.find('/', origin.find("://") + 3) == std::string::npos
                       ? ""
                       : "an origin is scheme://host[:port], as http://example.org:8080";
          },
          "ORIGIN"));
  app.add_option("--server-name", o.server_names,
                 "A name browsers reach the server by (a DNS name, a reverse proxy's), besides its "
                 "IP addresses, localhost, .local names and this machine's name, which its "
                 "page may open the WebSocket from (repeat it, or separate by commas)")
      ->envname("FLUIDCAST_SERVER_NAME")
      ->delimiter(',')
      ->check(CLI::Validator(
          [](std::string& name) -> std::string {
            const bool host_name =
                !name.empty() && name.size() <= 253 && name.front() != '.' &&
                name.find("..") == std::string::npos &&
                std::all_of(name.begin(), name.end(), [](unsigned char c) {
                  return std::isalnum(c) || c == '-' || c == '.';
                });
            return host_name ? "" : "a server name is a host name, as fluid.example.org";
          },
          "NAME"));
  app.add_option("--token-file", o.token_file,
                 "File whose first line is the token every client must send in Hello.token")
      ->envname("FLUIDCAST_TOKEN_FILE")
      ->check(CLI::ExistingFile);
  o.web_root = (program_folder() / FLUIDCAST_WEB_FROM_BINARY).lexically_normal().string();
  app.add_option("--web-root", o.web_root,
                 "Folder of the phone page: index.html, app.js, fluidcast.proto, vendor/")
      ->envname("FLUIDCAST_WEB_ROOT")
      ->check(CLI::ExistingDirectory);
  app.parse(argc, argv);
  if (o.tls_certificate.empty() != o.tls_key.empty()) {
    throw CLI::ValidationError("--tls-cert and --tls-key", "give both, or neither");
  }
  if (o.default_particles && *o.default_particles > l.max_particles) {
    throw CLI::ValidationError("--default-particles", "more than --max-particles");
  }
  if (o.target_fps && *o.target_fps > l.max_fps) {
    throw CLI::ValidationError("--target-fps", "more than --max-fps");
  }
  if (o.gpu_memory_mib != 0 && o.gpu_memory_mib < kBlockMib) {
    throw CLI::ValidationError("--gpu-memory", least_gpu_memory);
  }
  o.log_format = parse_log_format(log_format);
  l.max_sessions_per_address = sessions_per_address.value_or((l.max_sessions + 1) / 2);
  l.resume_grace = std::chrono::seconds(grace);
  l.idle_timeout = std::chrono::seconds(idle);
  l.hello_timeout = std::chrono::seconds(hello);
  o.backend = backend == "gpu"   ? SolverBackend::gpu
              : backend == "cpu" ? SolverBackend::cpu
                                 : SolverBackend::automatic;
  return o;
}

ServerLimits ServerOptions::limits_for(bool hardware, std::uint32_t fitting_particles) const {
  ServerLimits chosen = limits;
  if (!hardware) chosen.target_fps = 30;
  chosen.busy_share = busy_share.value_or(hardware ? chosen.busy_share : chosen.sim_share);
  chosen.default_particles =
      std::min(default_particles.value_or(fitting_particles), chosen.max_particles);
  chosen.target_fps = std::min(target_fps.value_or(chosen.target_fps), chosen.max_fps);
  return chosen;
}

}  // namespace fluidcast::server

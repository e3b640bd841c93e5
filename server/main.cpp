// fluidcast-server: headless. One GPU worker runs every session; gRPC serves the Stream and the
// unary calls; HTTP serves /metrics and /healthz. SIGINT or SIGTERM: stop accepting, end every
// stream with UNAVAILABLE, exit 0.
#include <arpa/inet.h>
#include <grpcpp/ext/proto_server_reflection_plugin.h>
#include <grpcpp/grpcpp.h>
#include <grpcpp/resource_quota.h>
#include <grpcpp/health_check_service_interface.h>
#include <ifaddrs.h>
#include <malloc.h>
#include <netinet/in.h>
#include <spdlog/spdlog.h>
#include <sys/resource.h>
#include <systemd/sd-daemon.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <optional>
#include <sstream>
#include <string>

#include "fluidcast/command_line.h"
#include "fluidcast/gpu/context.h"
#include "fluidcast/program_folder.h"
#include "fluidcast/render/frame_renderer.h"
#include "fluidcast/sim/solver_params.h"
#include "fluidcast/v1/wire_sizes.h"
#include "grpc/fluidcast_service.h"
#include "grpc/grpc_listener.h"
#include "grpc/grpc_log.h"
#include "log.h"
#include "options.h"
#include "session/default_size.h"
#include "session/session_hub.h"
#include "web/http_server.h"
#include "web/tls_certificate.h"
#include "web/websocket_session.h"

namespace fluidcast::server {
namespace {

// At shutdown, after gRPC's streams had theirs: how long WebSockets have to write the StreamEnd
// that says the server is going, and close.
constexpr std::chrono::seconds kWebSocketGoodbye{1};
// The least memory gRPC's buffers may hold in all (start_grpc).
constexpr std::size_t kLeastGrpcMemory = std::size_t(256) << 20;

std::string read_file(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

std::optional<std::string> read_token(const std::string& path) {
  if (path.empty()) return std::nullopt;
  std::ifstream in(path);
  std::string token;
  std::getline(in, token);
  // A file written on Windows ends its line in \r\n; a trailing space is no one's token either.
  token.erase(token.find_last_not_of(" \t\r") + 1);
  if (token.empty()) throw std::runtime_error("--token-file " + path + ": the first line is empty");
  return token;
}

// The IPv4 addresses a phone on the LAN can reach.
std::vector<std::string> lan_addresses() {
  std::vector<std::string> addresses;
  ifaddrs* list = nullptr;
  if (getifaddrs(&list) != 0) return addresses;
  for (ifaddrs* entry = list; entry; entry = entry->ifa_next) {
    if (!entry->ifa_addr || entry->ifa_addr->sa_family != AF_INET) continue;
    char text[INET_ADDRSTRLEN];
    const auto* address = reinterpret_cast<sockaddr_in*>(entry->ifa_addr);
    inet_ntop(AF_INET, &address->sin_addr, text, sizeof text);
    if (std::string(text) != "127.0.0.1") addresses.emplace_back(text);
  }
  freeifaddrs(list);
  return addresses;
}

// What the page's folder holds, by the path a browser asks for.
std::map<std::string, std::filesystem::path> page_routes(const std::filesystem::path& web) {
  std::map<std::string, std::filesystem::path> routes{{"/", web / "index.html"}};
  const std::string_view files = FLUIDCAST_PAGE_FILES;  // comma-separated (page_files.cmake)
  for (std::size_t at = 0; at < files.size();) {
    const std::size_t end = std::min(files.find(',', at), files.size());
    const std::string file(files.substr(at, end - at));
    routes["/" + file] = web / file;
    at = end + 1;
  }
  return routes;
}

bool gpu_solver_for(const ServerOptions& options, const gpu::Context& context) {
  switch (options.backend) {
    case SolverBackend::gpu:
      return true;
    case SolverBackend::cpu:
      return false;
    case SolverBackend::automatic:
      break;
  }
  return context.info().hardware();
}

// Descriptors are what idle connections use up: the soft limit goes up to the hard one (often
// 1024 against 524288). Returns the limit now.
rlim_t raise_descriptor_limit() {
  rlimit limit{};
  if (getrlimit(RLIMIT_NOFILE, &limit) != 0) return 1024;
  if (limit.rlim_cur < limit.rlim_max) {
    rlimit raised = limit;
    raised.rlim_cur = limit.rlim_max;
    if (setrlimit(RLIMIT_NOFILE, &raised) == 0) return raised.rlim_cur;
  }
  return limit.rlim_cur;
}

// The most particles that the sessions' solver keeps in real time within their share of this
// device, measured by a few steps at growing counts; said in the log.
std::uint32_t measure_default_particles(const ServerOptions& options, gpu::Context& context,
                                        bool gpu_solver) {
  const auto begun = std::chrono::steady_clock::now();
  const DefaultSize size = choose_default_particles(
      [&](std::uint32_t particles) {
        return measure_ms_per_substep(context, gpu_solver, particles);
      },
      options.limits.max_particles, 1.0 / sim::SolverParams{}.time_step, options.limits.sim_share);
  spdlog::info(
      "measured: {} particles simulate in real time in {:.0f} % of the device ({:.3f} ms a "
      "substep; {:.1f} s to measure; --default-particles to choose)",
      size.particles, 100.0 * size.device_share, size.ms_per_substep,
      std::chrono::duration<double>(std::chrono::steady_clock::now() - begun).count());
  return size.particles;
}

// The page's HTTPS: the operator's certificate, else one made for this machine's addresses.
struct PageTls {
  TlsFiles files;
  std::shared_ptr<boost::asio::ssl::context> context;
};
PageTls page_tls(const ServerOptions& options, const std::vector<std::string>& addresses) {
  const TlsFiles files =
      options.tls_certificate.empty()
          ? self_signed_certificate(options.state_dir.empty()
                                        ? default_state_folder()
                                        : std::filesystem::path(options.state_dir),
                                    addresses)
          : TlsFiles{options.tls_certificate, options.tls_key};
  auto context = std::make_shared<boost::asio::ssl::context>(boost::asio::ssl::context::tls_server);
  // Read once: another server sharing the state folder may put a new self-signed file (key and
  // certificate in one) in its place between two reads of it.
  const std::string certificate = read_file(files.certificate.string());
  const std::string key = files.key == files.certificate ? certificate : read_file(files.key.string());
  try {
    context->use_certificate_chain(boost::asio::buffer(certificate));
    context->use_private_key(boost::asio::buffer(key), boost::asio::ssl::context::pem);
  } catch (const std::exception& e) {
    throw std::runtime_error("TLS: " + files.certificate.string() + " and " + files.key.string() +
                             " are not a PEM certificate and its key: " + e.what());
  }
  return {files, std::move(context)};
}

// The gRPC server, with no port of its own: `listener` accepts its connections and hands them
// over, in TLS with --tls-cert, else in plaintext. The acceptor must outlive the listener's stop.
struct GrpcServer {
  std::unique_ptr<grpc::experimental::ExternalConnectionAcceptor> acceptor;
  std::unique_ptr<grpc::Server> server;  // null when gRPC could not start
};

GrpcServer start_grpc(const ServerOptions& options, const ServerLimits& limits,
                      FluidcastService& service, GrpcListener& listener) {
  grpc::EnableDefaultHealthCheckService(true);
  grpc::reflection::InitProtoReflectionServerBuilderPlugin();
  grpc::ServerBuilder builder;
  std::shared_ptr<grpc::ServerCredentials> credentials = grpc::InsecureServerCredentials();
  if (!options.tls_certificate.empty()) {
    grpc::SslServerCredentialsOptions tls;
    tls.pem_key_cert_pairs.push_back(
        {read_file(options.tls_key), read_file(options.tls_certificate)});
    credentials = grpc::SslServerCredentials(tls);
  }
  GrpcServer grpc;
  grpc.acceptor = builder.experimental().AddExternalConnectionAcceptor(
      grpc::ServerBuilder::experimental_type::ExternalConnectionType::FROM_FD, credentials);
  builder.RegisterService(&service);
  // A connection carries a stream and a few snapshot calls at a time, not thousands; one with no
  // call for a minute is closed (its descriptor is worth more than a client's reconnect).
  builder.AddChannelArgument(GRPC_ARG_MAX_CONCURRENT_STREAMS, 16);
  builder.AddChannelArgument(GRPC_ARG_MAX_CONNECTION_IDLE_MS, 60000);
  // Dead phones are noticed in seconds, not gRPC's default two hours.
  builder.AddChannelArgument(GRPC_ARG_KEEPALIVE_TIME_MS, 10000);
  builder.AddChannelArgument(GRPC_ARG_KEEPALIVE_TIMEOUT_MS, 5000);
  builder.AddChannelArgument(GRPC_ARG_KEEPALIVE_PERMIT_WITHOUT_CALLS, 1);
  builder.AddChannelArgument(GRPC_ARG_HTTP2_MIN_RECV_PING_INTERVAL_WITHOUT_DATA_MS, 5000);
  // A snapshot of the largest session, and room for the rest.
  const auto largest_message = static_cast<int>(std::min<std::uint64_t>(
      INT32_MAX, v1::kSnapshotBytesPerParticle * limits.max_particles + (1 << 20)));
  builder.SetMaxReceiveMessageSize(largest_message);
  // gRPC (1.51) buffers a message whole before it checks its size (grpc/grpc#43012): one stream
  // that declares 2 GB and sends it slowly would hold it all. Past its memory quota gRPC cancels
  // streams instead: room for four of the largest messages at once, and at least 256 MiB.
  grpc::ResourceQuota quota("fluidcast-grpc");
  quota.Resize(std::max<std::size_t>(kLeastGrpcMemory, 4 * std::size_t(largest_message)));
  builder.SetResourceQuota(quota);
  grpc.server = builder.BuildAndStart();
  if (grpc.server) listener.start(*grpc.acceptor);
  return grpc;
}

int grpc_address_in_use(const ServerOptions& options) {
  std::fprintf(stderr,
               "fluidcast-server: cannot listen for gRPC on %s:%u: the address is in use "
               "(another server?) or not one of this machine's (--listen, --grpc-port)\n",
               options.listen.c_str(), unsigned(options.grpc_port));
  return kBadFlag;
}

// Whether the server listens on every interface: IPv4's (0.0.0.0) or IPv6's and IPv4's (::).
bool every_interface(const std::string& listen) { return listen == "0.0.0.0" || listen == "::"; }

// What the operator reads at start: where to connect, from here and from a phone.
void log_where_to_connect(const ServerOptions& options, const ServerLimits& limits,
                          const gpu::DeviceInfo& device, const std::vector<std::string>& addresses,
                          const TlsFiles& tls_files, int grpc_port, int http_port) {
  spdlog::info("fluidcast-server {} listening: grpc={}:{} http={}:{} (and https)", kVersion,
               options.listen, grpc_port, options.listen, http_port);
  spdlog::info("device {}; limits: {} sessions, {} particles, {}x{}, {} fps", device.name,
               limits.max_sessions, limits.max_particles, limits.max_width, limits.max_height,
               limits.max_fps);
  spdlog::info(
      "new sessions: {} particles at {} frames/s{} (--default-particles, --target-fps; "
      "a page can ask: ?particles=N)",
      limits.default_particles, limits.target_fps,
      device.hardware() ? "" : " (the frame rate of a CPU device)");
  if (every_interface(options.listen)) {
    for (const std::string& address : addresses) {
      spdlog::info(
          "on a phone on this network, open https://{}:{}/ (tilt needs https; http:// "
          "works too) (gRPC: {}:{})",
          address, http_port, address, grpc_port);
    }
  }
  if (options.tls_certificate.empty()) {
    spdlog::info(
        "https uses a self-signed certificate, {}: a browser asks once to accept it "
        "(README: Connect your phone; --tls-cert for a real one)",
        tls_files.certificate.string());
  }
  const char* local = every_interface(options.listen) ? "127.0.0.1" : options.listen.c_str();
  // The client is installed beside the server by a build or a full install, not in the image.
  const std::filesystem::path client = program_folder() / "fluidcast-client";
  if (std::filesystem::exists(client)) {
    spdlog::info(
        "here: open http://{}:{}/ in a browser, or run {} --headless --server {}:{} --seconds 10",
        local, http_port, client.string(), local, grpc_port);
  } else {
    spdlog::info("here: open http://{}:{}/ in a browser", local, http_port);
  }
  for (const auto& [target, file] : page_routes(options.web_root)) {
    if (!std::filesystem::exists(file)) {
      spdlog::warn("the page lacks {} (--web-root): phones will not get it", file.string());
    }
  }
}

// The limits for this device, and connections within what descriptors allow.
ServerLimits limits_for_device(const ServerOptions& options, gpu::Context& context,
                               bool gpu_solver) {
  ServerLimits limits = options.limits_for(
      context.info().hardware(), options.default_particles
                                     ? *options.default_particles
                                     : measure_default_particles(options, context, gpu_solver));
  const rlim_t descriptors = raise_descriptor_limit();
  if (limits.max_connections > descriptors / 2) {
    limits.max_connections = static_cast<std::uint32_t>(std::max<rlim_t>(1, descriptors / 2));
    spdlog::info(
        "at most {} HTTP and WebSocket connections: half of the {} descriptors this "
        "process may open (--max-connections; raise the limit with ulimit -Hn or "
        "systemd's LimitNOFILE=)",
        limits.max_connections, descriptors);
  }
  return limits;
}

// SIGINT and SIGTERM reach only the main thread, which waits for them (serve).
sigset_t block_stop_signals() {
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  return signals;
}

gpu::ContextOptions context_options(const ServerOptions& options) {
  gpu::ContextOptions context = gpu::options_from_environment();
  if (options.device) context.device_index = options.device;
  context.memory_limit_bytes = std::uint64_t{options.gpu_memory_mib} << 20;
  context.log = [](const std::string& line) { spdlog::info("{}", line); };
  return context;
}

// After the first stop signal: streams go on for --drain-seconds, or until a second signal.
void drain(const sigset_t& signals, int signal, const ServerOptions& options) {
  if (options.drain_seconds <= 0) return;
  spdlog::info("{}: draining for {} s (/healthz 503; streams go on)",
               signal == SIGINT ? "SIGINT" : "SIGTERM", options.drain_seconds);
  const timespec period{static_cast<time_t>(options.drain_seconds), 0};
  sigtimedwait(&signals, nullptr, &period);
}

// --list-devices: what an operator with several GPUs needs to give each server its own
// (docs/operations.md, Many GPUs).
int print_devices() {
  const std::vector<gpu::DeviceInfo> devices = gpu::list_devices();
  const std::optional<std::uint32_t> best = gpu::best_device(devices);
  std::printf("Vulkan devices (--device N or FLUIDCAST_DEVICE=N picks one):\n");
  for (const gpu::DeviceInfo& device : devices) {
    std::printf("%s%s\n", device.describe().c_str(), device.index == best ? " [the default]" : "");
  }
  return 0;
}

int serve(const ServerOptions& options) {
  const sigset_t signals = block_stop_signals();
  configure_log(options.log_format);
  route_grpc_log();
  gpu::Context context(context_options(options));
  const bool gpu_solver = gpu_solver_for(options, context);
  spdlog::info("sessions simulate on the {}",
               gpu_solver ? "GPU" : "CPU (the Vulkan device is a CPU; it renders only)");
  if (const auto why = render::FrameRenderer::mc_unsupported(context)) {
    spdlog::warn("{}; viewers get ssfr", *why);
  }

  Metrics metrics;
  metrics.describe_device(context.info());
  const ServerLimits limits = limits_for_device(options, context, gpu_solver);
  SessionHub hub(context, gpu_solver, limits, read_token(options.token_file), metrics);
  // gRPC's connections are accepted by a listener of ours (grpc_listener.h). Their total is
  // what descriptors allow (the listener waits when they run out); from one address, as many as
  // HTTP allows.
  std::optional<GrpcListener> grpc_listener;
  try {
    grpc_listener.emplace(options.listen, options.grpc_port,
                          ConnectionLimits(std::numeric_limits<std::uint32_t>::max(),
                                           limits.max_connections_per_address));
  } catch (const std::runtime_error&) {
    return grpc_address_in_use(options);
  }
  FluidcastService service(hub);
  const std::vector<std::string> addresses = lan_addresses();
  const PageTls tls = page_tls(options, addresses);

  // HTTP before gRPC's server: if its port is taken, no stream has started yet. /healthz is
  // unhealthy from SIGTERM on, and while either port cannot accept for want of descriptors.
  std::atomic<bool> serving{true};
  HttpServer http(options.listen, options.http_port,
                  {[&] { return metrics.prometheus_text(); },
                   [&] { return serving.load() && grpc_listener->accepting(); },
                   [&hub](WebStream stream,
                          boost::beast::http::request<boost::beast::http::string_body> request,
                          std::shared_ptr<ConnectionLimits::Slot> slot) {
                     serve_websocket(std::move(stream), std::move(request), std::move(slot), hub);
                   },
                   page_routes(options.web_root),
                   WebSocketOrigins(options.allowed_origins, options.server_names,
                                    this_machine_name())},
                  ConnectionLimits(limits.max_connections, limits.max_connections_per_address),
                  tls.context);
  const GrpcServer grpc = start_grpc(options, limits, service, *grpc_listener);
  if (!grpc.server) {
    std::fprintf(stderr, "fluidcast-server: gRPC could not start (its log above says why)\n");
    return 1;
  }
  const int grpc_port = grpc_listener->port();
  // The listener hands connections to `grpc`: it stops before `grpc` goes, however serve() ends
  // (at shutdown it is stopped earlier, before the streams end).
  const std::unique_ptr<GrpcListener, void (*)(GrpcListener*)> stop_listener(
      &*grpc_listener, [](GrpcListener* listener) { listener->stop(); });
  grpc::HealthCheckServiceInterface* health = grpc.server->GetHealthCheckService();
  health->SetServingStatus(true);
  log_where_to_connect(options, limits, context.info(), addresses, tls.files, grpc_port,
                       http.port());

  // Under systemd (Type=notify): started once every port listens; stopping from the signal on.
  sd_notifyf(0, "READY=1\nSTATUS=serving: grpc %d, http %d", grpc_port, http.port());
  int signal = 0;
  sigwait(&signals, &signal);
  sd_notify(0, "STOPPING=1");
  serving = false;
  health->SetServingStatus(false);
  drain(signals, signal, options);
  spdlog::info("ending every stream");
  hub.stop();  // every stream ends with UNAVAILABLE; new ones are refused
  grpc_listener->stop();
  grpc.server->Shutdown(std::chrono::system_clock::now() + std::chrono::seconds(3));
  http.stop(kWebSocketGoodbye);
  spdlog::info("stopped");
  return 0;
}

}  // namespace
}  // namespace fluidcast::server

int main(int argc, char** argv) {
  // glibc gives each thread that allocates its own arena, up to 8 per core, and memory freed in
  // one is not reused by another: sessions of 200 000 particles opened and closed one after
  // another grew the server by ~25 MB each on two cores (flat with 4 arenas, measured). What the
  // threads sharing 4 arenas cost in lock contention was not measured.
  mallopt(M_ARENA_MAX, 4);
  const auto options = fluidcast::server::parse_server_options(argc, argv);
  try {
    if (options.list_devices) return fluidcast::server::print_devices();
    return fluidcast::server::serve(options);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fluidcast-server: %s\n", e.what());
    return fluidcast::kBadFlag;
  }
}

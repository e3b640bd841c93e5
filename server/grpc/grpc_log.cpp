#include "grpc/grpc_log.h"

#include <grpc/support/log.h>
#include <spdlog/spdlog.h>

#include <atomic>
#include <string_view>

namespace fluidcast::server {
namespace {

std::atomic<bool> acceptor_failed{false};

void log_line(gpr_log_func_args* line) {
  const std::string_view message = line->message;
  if (message.find("Failed accept4") != std::string_view::npos && !acceptor_failed.exchange(true)) {
    spdlog::error(
        "gRPC stopped accepting connections for good ({}): /healthz says 503 from now on; "
        "restart the server (docs/operations.md, Connections and descriptors)",
        message);
    return;
  }
  const auto level = line->severity == GPR_LOG_SEVERITY_ERROR  ? spdlog::level::err
                     : line->severity == GPR_LOG_SEVERITY_INFO ? spdlog::level::info
                                                               : spdlog::level::debug;
  spdlog::log(level, "gRPC: {} ({}:{})", message, line->file, line->line);
}

}  // namespace

void route_grpc_log() { gpr_set_log_function(log_line); }

bool grpc_acceptor_failed() { return acceptor_failed.load(); }

}  // namespace fluidcast::server

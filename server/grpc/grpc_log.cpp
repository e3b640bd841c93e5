#include "grpc/grpc_log.h"

#include <grpc/support/log.h>
#include <spdlog/spdlog.h>

#include <string_view>

namespace fluidcast::server {
namespace {

void log_line(gpr_log_func_args* line) {
  const std::string_view message = line->message;
  const auto level = line->severity == GPR_LOG_SEVERITY_ERROR  ? spdlog::level::err
                     : line->severity == GPR_LOG_SEVERITY_INFO ? spdlog::level::info
                                                               : spdlog::level::debug;
  spdlog::log(level, "gRPC: {} ({}:{})", message, line->file, line->line);
}

}  // namespace

void route_grpc_log() { gpr_set_log_function(log_line); }

}  // namespace fluidcast::server

// A Refusal as a gRPC status.
#pragma once

#include <grpcpp/support/status.h>

#include "session/refusal.h"

namespace fluidcast::server {

// RefusalCode's values are gRPC's own.
static_assert(int(RefusalCode::cancelled) == grpc::StatusCode::CANCELLED &&
              int(RefusalCode::invalid_argument) == grpc::StatusCode::INVALID_ARGUMENT &&
              int(RefusalCode::deadline_exceeded) == grpc::StatusCode::DEADLINE_EXCEEDED &&
              int(RefusalCode::not_found) == grpc::StatusCode::NOT_FOUND &&
              int(RefusalCode::permission_denied) == grpc::StatusCode::PERMISSION_DENIED &&
              int(RefusalCode::resource_exhausted) == grpc::StatusCode::RESOURCE_EXHAUSTED &&
              int(RefusalCode::failed_precondition) == grpc::StatusCode::FAILED_PRECONDITION &&
              int(RefusalCode::internal) == grpc::StatusCode::INTERNAL &&
              int(RefusalCode::unavailable) == grpc::StatusCode::UNAVAILABLE &&
              int(RefusalCode::unauthenticated) == grpc::StatusCode::UNAUTHENTICATED);

inline grpc::Status to_status(const Refusal& refusal) {
  return grpc::Status(static_cast<grpc::StatusCode>(refusal.code()), refusal.what());
}

}  // namespace fluidcast::server

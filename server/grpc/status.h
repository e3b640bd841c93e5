// A Refusal as a gRPC status.
#pragma once

#include <grpcpp/support/status.h>

#include "session/refusal.h"

namespace fluidcast::server {

inline grpc::Status to_status(const Refusal& refusal) {
  const grpc::StatusCode code = [&] {
    switch (refusal.code()) {
      case RefusalCode::invalid_argument:
        return grpc::StatusCode::INVALID_ARGUMENT;
      case RefusalCode::unauthenticated:
        return grpc::StatusCode::UNAUTHENTICATED;
      case RefusalCode::permission_denied:
        return grpc::StatusCode::PERMISSION_DENIED;
      case RefusalCode::not_found:
        return grpc::StatusCode::NOT_FOUND;
      case RefusalCode::resource_exhausted:
        return grpc::StatusCode::RESOURCE_EXHAUSTED;
      case RefusalCode::failed_precondition:
        return grpc::StatusCode::FAILED_PRECONDITION;
      case RefusalCode::unavailable:
        return grpc::StatusCode::UNAVAILABLE;
      case RefusalCode::internal:
        return grpc::StatusCode::INTERNAL;
      case RefusalCode::deadline_exceeded:
        return grpc::StatusCode::DEADLINE_EXCEEDED;
    }
    return grpc::StatusCode::INTERNAL;
  }();
  return grpc::Status(code, refusal.what());
}

}  // namespace fluidcast::server

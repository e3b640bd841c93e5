// Why the server refuses a client's request, in words a client developer can act on. Transports
// map the code to their own (gRPC status codes; the WebSocket close reason carries the same).
#pragma once

#include <stdexcept>
#include <string>

namespace fluidcast::server {

enum class RefusalCode {
  invalid_argument,
  unauthenticated,
  permission_denied,  // the viewer's key only views, and the request would change the fluid
  not_found,
  resource_exhausted,
  failed_precondition,
  unavailable,
  internal,  // the server failed (out of GPU memory, a device lost): not the client's doing
  deadline_exceeded,  // no viewer's input for ServerLimits::idle_timeout, or no Hello in time
};

// The code's name as gRPC spells it: the WebSocket's close reason and the metrics' label.
inline const char* refusal_code_name(RefusalCode code) {
  switch (code) {
    case RefusalCode::invalid_argument:
      return "INVALID_ARGUMENT";
    case RefusalCode::unauthenticated:
      return "UNAUTHENTICATED";
    case RefusalCode::permission_denied:
      return "PERMISSION_DENIED";
    case RefusalCode::not_found:
      return "NOT_FOUND";
    case RefusalCode::resource_exhausted:
      return "RESOURCE_EXHAUSTED";
    case RefusalCode::failed_precondition:
      return "FAILED_PRECONDITION";
    case RefusalCode::unavailable:
      return "UNAVAILABLE";
    case RefusalCode::internal:
      return "INTERNAL";
    case RefusalCode::deadline_exceeded:
      return "DEADLINE_EXCEEDED";
  }
  return "INTERNAL";
}

class Refusal : public std::runtime_error {
 public:
  Refusal(RefusalCode code, const std::string& message)
      : std::runtime_error(message), code_(code) {}
  RefusalCode code() const { return code_; }

 private:
  RefusalCode code_;
};

}  // namespace fluidcast::server

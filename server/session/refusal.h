// Why the server refuses a client's request, in words a client developer can act on. Transports
// map the code to their own (gRPC status codes; the WebSocket close reason carries the same).
#pragma once

#include <stdexcept>
#include <string>

namespace fluidcast::server {

enum class RefusalCode {
  invalid_argument,
  unauthenticated,
  not_found,
  resource_exhausted,
  failed_precondition,
  unavailable,
  internal,  // the server failed (out of GPU memory, a device lost): not the client's doing
  deadline_exceeded,  // the session idled out: no viewer's input for ServerLimits::idle_timeout
};

class Refusal : public std::runtime_error {
 public:
  Refusal(RefusalCode code, const std::string& message)
      : std::runtime_error(message), code_(code) {}
  RefusalCode code() const { return code_; }

 private:
  RefusalCode code_;
};

}  // namespace fluidcast::server

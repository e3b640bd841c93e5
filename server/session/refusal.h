// Why the server refuses a client's request, in words a client developer can act on. Transports
// carry the code as it is (a gRPC status) or by its name (the WebSocket's StreamEnd).
#pragma once

#include <stdexcept>
#include <string>

namespace fluidcast::server {

// The values are the canonical status codes (google.rpc.Code), which gRPC's StatusCode shares.
enum class RefusalCode {
  cancelled = 1,  // the client cancelled its call while it waited its turn
  invalid_argument = 3,
  deadline_exceeded = 4,  // no viewer's input for ServerLimits::idle_timeout, or no Hello in time
  not_found = 5,
  permission_denied = 7,   // the viewer's key only views, and the request would change the fluid
  resource_exhausted = 8,  // a limit, or GPU memory for what the request asks (frames, particles)
  failed_precondition = 9,
  internal = 13,  // the server failed (a device lost): not the client's doing
  unavailable = 14,
  unauthenticated = 16,
};

// The code's name as gRPC spells it: the WebSocket's close reason and the metrics' label.
inline const char* refusal_code_name(RefusalCode code) {
  switch (code) {
    case RefusalCode::cancelled:
      return "CANCELLED";
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

// A request the GPU had no memory for (a gpu::VulkanError that is out_of_memory(): other sessions
// hold it, or --gpu-memory is met): RESOURCE_EXHAUSTED naming `field`, what found no room, the
// device's word for it and what the client can do instead.
inline Refusal no_gpu_memory(const std::string& field, const std::string& room_for,
                             const std::exception& error, const std::string& instead) {
  return Refusal(RefusalCode::resource_exhausted, field + ": the server's GPU has no memory for " +
                                                      room_for + " now (" + error.what() + "); " +
                                                      instead);
}

}  // namespace fluidcast::server

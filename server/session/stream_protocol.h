// What one stream's messages mean, whichever transport carries them (gRPC's Stream, the page's
// WebSocket): the first must be a Hello, which opens a session; each later one is an event for
// it, checked against its viewer's access and the stream's rates. A transport reads a message,
// hands its bytes here and does what comes back; a Refusal thrown ends the stream with its status
// (record_refusal counts and logs it). A transport reads the next message only after the last one's
// answer, and after opened() once it opened a session, so this needs no lock.
#pragma once

#include <google/protobuf/io/zero_copy_stream.h>

#include <variant>

#include "access.h"
#include "fluidcast/v1/fluidcast.pb.h"
#include "metrics.h"
#include "refusal.h"
#include "server_limits.h"
#include "validation.h"

namespace fluidcast::server {

// Counts a refusal that ended a stream of `transport`, and logs it: each transport once, as the
// stream ends, whatever ended it (this protocol's rules, the session, the Hello deadline).
void record_refusal(Metrics& metrics, Transport transport, const Refusal& refusal);

class StreamProtocol {
 public:
  // `limits` and `token` outlive it.
  StreamProtocol(const ServerLimits& limits, const std::optional<std::string>& token);

  // Open a session (create, join or resume) for this Hello; the next message waits for opened().
  struct Open {
    v1::Hello hello;
  };
  // Post this event to the stream's session.
  struct Post {
    v1::ClientMessage message;
  };
  // The next message's bytes. Throws a Refusal for bytes that are not a ClientMessage, a message
  // that breaks a rule, or one beyond its kind's rate.
  std::variant<Open, Post> receive(google::protobuf::io::ZeroCopyInputStream& bytes);
  // The session opened: later events are checked against `access`.
  void opened(Access access);

  // Why a stream that sent no Hello within ServerLimits::hello_timeout ends.
  Refusal no_hello() const;

 private:
  enum class Stage { awaiting_hello, opening, open };

  const ServerLimits* limits_;
  const std::optional<std::string>* token_;
  StreamRates rates_;
  Stage stage_ = Stage::awaiting_hello;
  Access access_ = Access::view;
};

}  // namespace fluidcast::server

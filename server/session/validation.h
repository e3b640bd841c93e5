// Checks every client message at the transport adapter, before it reaches a session: what breaks
// a rule of the protocol (proto/fluidcast/v1/fluidcast.proto) throws a Refusal naming the rule.
#pragma once

#include <chrono>
#include <optional>
#include <string>

#include "access.h"
#include "fluidcast/v1/fluidcast.pb.h"
#include "server_limits.h"

namespace fluidcast::server {

// The first message of a stream: a Hello with a token when the server wants one, a viewport and
// quality within the limits, and a session to create (valid scene, solver and count), join or
// resume.
void validate_hello(const v1::ClientMessage& message, const ServerLimits& limits,
                    const std::optional<std::string>& token);

// Every later message: input within its ranges, never a second Hello, and nothing that changes
// the fluid from a viewer without control (PERMISSION_DENIED).
void validate_event(const v1::ClientMessage& message, const ServerLimits& limits, Access access);

// Parts shared with the other requests.
void validate_viewport(const v1::Viewport& viewport);
void validate_quality(const v1::Quality& quality, const ServerLimits& limits);
// A key as a client gives it (join, resume, snapshots): not empty, not overlong.
void validate_key(const std::string& key, const char* field);
// The token a request gives in `field`, when the server has one.
void validate_token(const std::string& given, const std::optional<std::string>& token,
                    const char* field);
// A scene's or solver's name in `field`: empty (the default) or one of InputRules' names.
void validate_scene(const std::string& scene, const char* field);
void validate_solver(const std::string& solver, const char* field);
// A snapshot's simulated time (InputRules.snapshot_seconds), in `field`.
void validate_snapshot_time(double seconds, const char* field);

// Input events allowed per second, with a burst of one second's worth: a token bucket.
class InputRateLimit {
 public:
  explicit InputRateLimit(std::uint32_t per_second);
  // False when the stream has sent more than the rate allows.
  bool allow(std::chrono::steady_clock::time_point now);

 private:
  double per_second_;
  double tokens_;
  std::chrono::steady_clock::time_point last_;
};

inline constexpr std::uint32_t kAcknowledgementsPerFrame = 4;

// One stream's rates: input events, acknowledgements (a few per frame the server may send) and
// state requests, each limited apart.
struct StreamRates {
  explicit StreamRates(const ServerLimits& limits);
  InputRateLimit input, acks, states;
};

// A message beyond its kind's rate throws RESOURCE_EXHAUSTED naming the limit.
void check_rate(const v1::ClientMessage& message, StreamRates& rates, const ServerLimits& limits);

}  // namespace fluidcast::server

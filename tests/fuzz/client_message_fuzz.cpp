// Fuzz target: any bytes as a stream's ClientMessage, first (a Hello) and later (an event, for a
// viewer that controls and one that only watches), through the checks every transport runs.
// A Refusal is the answer to bad input; anything else escaping is a defect.
#include <google/protobuf/stubs/logging.h>

#include <cstddef>
#include <cstdint>

#include "session/refusal.h"
#include "session/validation.h"

using namespace fluidcast;

// Protobuf logs every invalid UTF-8 string it refuses: thousands of lines, none of them a finding.
static const bool kQuiet = (google::protobuf::SetLogHandler(nullptr), true);

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  v1::ClientMessage message;
  if (!message.ParseFromArray(data, static_cast<int>(size))) return 0;
  static const server::ServerLimits limits;
  static server::StreamRates rates(limits);
  const std::optional<std::string> token = std::string("secret");
  for (const auto& check : {+[](const v1::ClientMessage&m, const std::optional<std::string>&t) {
                              server::validate_hello(m, limits, t);
                            },
                            +[](const v1::ClientMessage&m, const std::optional<std::string>&) {
                              server::validate_event(m, limits, server::Access::control);
                            },
                            +[](const v1::ClientMessage&m, const std::optional<std::string>&) {
                              server::validate_event(m, limits, server::Access::view);
                            },
                            +[](const v1::ClientMessage&m, const std::optional<std::string>&) {
                              server::check_rate(m, rates, limits);
                            }}) {
    try {
      check(message, token);
    } catch (const server::Refusal&) {
    }
  }
  return 0;
}

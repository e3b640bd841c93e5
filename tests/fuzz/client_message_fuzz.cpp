// Fuzz target: any bytes as a stream's message, through the StreamProtocol both transports use —
// as the first message (a Hello), and as a later one for a viewer that controls and one that only
// watches (these two streams live across inputs, so floods reach the rate limits).
// A Refusal is the answer to bad input; anything else escaping is a defect.
#include <google/protobuf/io/zero_copy_stream_impl_lite.h>
#include <google/protobuf/stubs/logging.h>

#include <cstddef>
#include <cstdint>

#include "session/stream_protocol.h"

using namespace fluidcast;
using namespace fluidcast::server;

// Protobuf logs every invalid UTF-8 string it refuses: thousands of lines, none of them a finding.
static const bool kQuiet = (google::protobuf::SetLogHandler(nullptr), true);

namespace {

const ServerLimits kLimits;
const std::optional<std::string> kToken = std::string("secret");

void receive(StreamProtocol& protocol, const std::uint8_t* data, std::size_t size) {
  google::protobuf::io::ArrayInputStream bytes(data, static_cast<int>(size));
  try {
    protocol.receive(bytes);
  } catch (const Refusal&) {
  }
}

StreamProtocol opened(Access access) {
  StreamProtocol protocol(kLimits, kToken);
  v1::ClientMessage hello;
  hello.mutable_hello()->set_token(*kToken);
  hello.mutable_hello()->mutable_viewport()->set_width(320);
  hello.mutable_hello()->mutable_viewport()->set_height(240);
  const std::string bytes = hello.SerializeAsString();
  receive(protocol, reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size());
  protocol.opened(access);
  return protocol;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static StreamProtocol controls = opened(Access::control), watches = opened(Access::view);
  StreamProtocol first(kLimits, kToken);
  receive(first, data, size);
  receive(controls, data, size);
  receive(watches, data, size);
  return 0;
}

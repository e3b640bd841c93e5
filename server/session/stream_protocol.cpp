#include "stream_protocol.h"

#include <spdlog/spdlog.h>

#include <stdexcept>

namespace fluidcast::server {

StreamProtocol::StreamProtocol(const ServerLimits& limits, const std::optional<std::string>& token)
    : limits_(&limits), token_(&token), rates_(limits) {}

std::variant<StreamProtocol::Open, StreamProtocol::Post> StreamProtocol::receive(
    google::protobuf::io::ZeroCopyInputStream& bytes) {
  if (stage_ == Stage::opening) throw std::logic_error("a message read while its session opens");
  v1::ClientMessage message;
  if (!message.ParseFromZeroCopyStream(&bytes)) {
    throw Refusal(RefusalCode::invalid_argument,
                  "a message of " + std::to_string(bytes.ByteCount()) +
                      " bytes that is not a fluidcast.v1.ClientMessage");
  }
  // Fields this server does not know (a newer client's) are not kept while the message waits.
  message.DiscardUnknownFields();
  if (stage_ == Stage::awaiting_hello) {
    validate_hello(message, *limits_, *token_);
    stage_ = Stage::opening;
    return Open{std::move(*message.mutable_hello())};
  }
  validate_event(message, *limits_, access_);
  check_rate(message, rates_, *limits_);
  return Post{std::move(message)};
}

void StreamProtocol::opened(Access access) {
  access_ = access;
  stage_ = Stage::open;
}

Refusal StreamProtocol::no_hello() const {
  return Refusal(RefusalCode::deadline_exceeded,
                 "no Hello within " + std::to_string(limits_->hello_timeout.count()) +
                     " s of the stream opening");
}

void record_refusal(Metrics& metrics, Transport transport, const Refusal& refusal) {
  metrics.refused(transport, refusal.code());
  spdlog::warn("ended a {} stream: {}", transport_name(transport), refusal.what());
}

}  // namespace fluidcast::server

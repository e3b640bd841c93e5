// A stream's messages as the protocol reads them, without a transport: the Hello first, then
// events checked against the viewer's access and the stream's rates; each refusal with its code.
#include "session/stream_protocol.h"

#include <google/protobuf/io/zero_copy_stream_impl_lite.h>
#include <gtest/gtest.h>

#include <functional>
#include <stdexcept>

namespace fluidcast::server {
namespace {

using Received = std::variant<StreamProtocol::Open, StreamProtocol::Post>;

Received receive(StreamProtocol& protocol, const std::string& bytes) {
  google::protobuf::io::ArrayInputStream input(bytes.data(), static_cast<int>(bytes.size()));
  return protocol.receive(input);
}
Received receive(StreamProtocol& protocol, const v1::ClientMessage& message) {
  return receive(protocol, message.SerializeAsString());
}

Refusal refusal_of(const std::function<void()>& act) {
  try {
    act();
  } catch (const Refusal& refusal) {
    return refusal;
  }
  ADD_FAILURE() << "accepted";
  return Refusal(RefusalCode::internal, "accepted");
}

v1::ClientMessage hello() {
  v1::ClientMessage message;
  message.mutable_hello()->mutable_viewport()->set_width(320);
  message.mutable_hello()->mutable_viewport()->set_height(240);
  return message;
}

v1::ClientMessage tilt() {
  v1::ClientMessage message;
  message.set_event_id(1);
  message.mutable_tilt()->set_y(-9.81f);
  return message;
}

class StreamProtocolTest : public testing::Test {
 protected:
  ServerLimits limits;
  std::optional<std::string> token;
  StreamProtocol protocol{limits, token};
};

TEST_F(StreamProtocolTest, AHelloOpensThenEventsArePostedInTheOrderTheyCame) {
  const Received opening = receive(protocol, hello());
  ASSERT_TRUE(std::holds_alternative<StreamProtocol::Open>(opening));
  EXPECT_EQ(std::get<StreamProtocol::Open>(opening).hello.viewport().width(), 320u);
  // Nothing is read while the session opens: a transport that did would be wrong.
  EXPECT_THROW(receive(protocol, tilt()), std::logic_error);
  protocol.opened(Access::control);
  const Received event = receive(protocol, tilt());
  ASSERT_TRUE(std::holds_alternative<StreamProtocol::Post>(event));
  EXPECT_FLOAT_EQ(std::get<StreamProtocol::Post>(event).message.tilt().y(), -9.81f);
}

TEST_F(StreamProtocolTest, BytesThatAreNotAClientMessageAreInvalidArgument) {
  const Refusal refusal = refusal_of([&] { receive(protocol, std::string("\xff\xff\xff")); });
  EXPECT_EQ(refusal.code(), RefusalCode::invalid_argument);
  EXPECT_STREQ(refusal.what(), "a message of 3 bytes that is not a fluidcast.v1.ClientMessage");
}

TEST_F(StreamProtocolTest, TheFirstMessageMustBeAHelloAndOnlyTheFirst) {
  EXPECT_EQ(refusal_of([&] { receive(protocol, tilt()); }).code(),
            RefusalCode::failed_precondition);
  receive(protocol, hello());
  protocol.opened(Access::control);
  EXPECT_EQ(refusal_of([&] { receive(protocol, hello()); }).code(),
            RefusalCode::failed_precondition);
}

TEST_F(StreamProtocolTest, AWatcherCannotTiltTheFluid) {
  receive(protocol, hello());
  protocol.opened(Access::view);
  EXPECT_EQ(refusal_of([&] { receive(protocol, tilt()); }).code(), RefusalCode::permission_denied);
}

TEST_F(StreamProtocolTest, InputBeyondItsRateIsResourceExhausted) {
  receive(protocol, hello());
  protocol.opened(Access::control);
  const Refusal refusal = refusal_of([&] {
    for (std::uint32_t k = 0; k <= 2 * limits.max_input_events_per_second; ++k) {
      receive(protocol, tilt());
    }
  });
  EXPECT_EQ(refusal.code(), RefusalCode::resource_exhausted);
}

// Fields this server does not know (a newer client's, or padding) are not kept while a message
// waits for its session.
TEST_F(StreamProtocolTest, UnknownFieldsAreDropped) {
  receive(protocol, hello());
  protocol.opened(Access::control);
  v1::ClientMessage padded = tilt();
  google::protobuf::UnknownFieldSet& unknown =
      *padded.GetReflection()->MutableUnknownFields(&padded);
  unknown.AddLengthDelimited(1000, std::string(1000, 'x'));
  const Received event = receive(protocol, padded);
  ASSERT_TRUE(std::holds_alternative<StreamProtocol::Post>(event));
  EXPECT_EQ(std::get<StreamProtocol::Post>(event).message.ByteSizeLong(), tilt().ByteSizeLong());
}

TEST_F(StreamProtocolTest, ARefusalIsCountedByTransportAndCode) {
  Metrics metrics;
  record_refusal(metrics, Transport::websocket, protocol.no_hello());
  EXPECT_NE(metrics.prometheus_text().find("fluidcast_streams_refused_total{transport="
                                           "\"websocket\",reason=\"DEADLINE_EXCEEDED\"} 1"),
            std::string::npos);
  EXPECT_STREQ(protocol.no_hello().what(), "no Hello within 10 s of the stream opening");
}

}  // namespace
}  // namespace fluidcast::server

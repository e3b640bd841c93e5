// The client library against a server that misbehaves on purpose (a stand-in service here, not
// fluidcast-server): a caller's sends never wait on the network, a server that stops reading
// ends the stream with a status that says so, and finishing never waits without end.
#include "stream_client.h"

#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <functional>
#include <stop_token>
#include <thread>
#include <utility>

namespace fluidcast::client {
namespace {

// What a handoff carries on from: a loss, not the server's refusal. gRPC's quota cancel arrives as
// RESOURCE_EXHAUSTED from a bare RST_STREAM (status_conversion: ENHANCE_YOUR_CALM), the message
// as a client received it (docs/operations.md, Memory); the server's own refusals say why.
TEST(StreamLostTest, ALossOrAQuotaCancelIsLostAndTheServersRefusalsAreNot) {
  EXPECT_TRUE(stream_lost({grpc::StatusCode::UNAVAILABLE, "the server is stopping"}));
  EXPECT_TRUE(stream_lost(
      {grpc::StatusCode::RESOURCE_EXHAUSTED, "Received RST_STREAM with error code 11"}));
  EXPECT_FALSE(stream_lost({grpc::StatusCode::RESOURCE_EXHAUSTED,
                            "this server holds at most 8 sessions (--max-sessions)"}));
  EXPECT_FALSE(stream_lost({grpc::StatusCode::INVALID_ARGUMENT, "Viewport: width 0"}));
  EXPECT_FALSE(stream_lost({grpc::StatusCode::DEADLINE_EXCEEDED, "idle for 600 s"}));
  EXPECT_FALSE(stream_lost(grpc::Status::OK));
}

// Welcomes, then never reads again until the client goes away; takes snapshot calls and never
// answers them.
class ServerThatStopsReading final : public v1::Fluidcast::Service {
 public:
  grpc::Status GetSnapshot(grpc::ServerContext* context, const v1::SnapshotRequest*,
                           v1::Snapshot*) override {
    while (!context->IsCancelled()) std::this_thread::sleep_for(std::chrono::milliseconds(20));
    return grpc::Status::CANCELLED;
  }
  grpc::Status Stream(
      grpc::ServerContext* context,
      grpc::ServerReaderWriter<v1::ServerMessage, v1::ClientMessage>* stream) override {
    v1::ClientMessage hello;
    if (!stream->Read(&hello)) return grpc::Status::CANCELLED;
    if (hello.hello().token() == "mute") {  // takes the stream, never answers
      while (!context->IsCancelled()) std::this_thread::sleep_for(std::chrono::milliseconds(20));
      return grpc::Status::CANCELLED;
    }
    v1::ServerMessage welcome;
    welcome.mutable_welcome()->set_viewer_id(1);
    stream->Write(welcome);
    while (!context->IsCancelled()) std::this_thread::sleep_for(std::chrono::milliseconds(20));
    return grpc::Status::CANCELLED;
  }
};

class StreamClientTest : public ::testing::Test {
 protected:
  void SetUp() override {
    grpc::ServerBuilder builder;
    builder.AddListeningPort("127.0.0.1:0", grpc::InsecureServerCredentials(), &port_);
    builder.RegisterService(&service_);
    server_ = builder.BuildAndStart();
    ASSERT_GT(port_, 0);
  }
  void TearDown() override {
    if (server_) server_->Shutdown(std::chrono::system_clock::now() + std::chrono::seconds(1));
  }

  ServerThatStopsReading service_;
  int port_ = 0;
  std::unique_ptr<grpc::Server> server_;
};

TEST_F(StreamClientTest, SendsNeverWaitAndAServerThatStopsReadingEndsTheStream) {
  StreamClient client(connect("127.0.0.1:" + std::to_string(port_)), v1::Hello{});
  v1::ClientMessage move;
  move.mutable_pointer()->set_phase(v1::PointerEvent::MOVE);
  move.mutable_pointer()->set_x(0.5f);
  move.mutable_pointer()->set_y(0.5f);
  // Far more than the transport's windows hold: the writer blocks, the queue fills.
  const auto start = std::chrono::steady_clock::now();
  std::uint64_t accepted = 0;
  for (int k = 0; k < 400000 && !client.ended(); ++k) accepted += client.send(move) != 0 ? 1 : 0;
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_LT(seconds, 10.0) << "a send waited on the network";
  EXPECT_GE(accepted, StreamClient::kMaxOutgoing);
  EXPECT_EQ(client.send(move), 0u) << "a send after the overflow was taken";
  for (int k = 0; k < 500 && !client.ended(); ++k) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ASSERT_TRUE(client.ended());
  EXPECT_EQ(client.status().error_code(), grpc::StatusCode::UNAVAILABLE);
  EXPECT_NE(client.end_reason().find("stopped reading"), std::string::npos) << client.end_reason();
}

TEST_F(StreamClientTest, AServerThatNeverWelcomesIsGivenUpOn) {
  v1::Hello hello;
  hello.set_token("mute");
  const auto start = std::chrono::steady_clock::now();
  try {
    StreamClient client(connect("127.0.0.1:" + std::to_string(port_)), hello,
                        std::chrono::milliseconds(500));
    ADD_FAILURE() << "a stream without a Welcome was taken";
  } catch (const StreamError& e) {
    EXPECT_EQ(e.code(), grpc::StatusCode::UNAVAILABLE);
    EXPECT_NE(std::string(e.what()).find("no Welcome within 500 ms"), std::string::npos)
        << e.what();
  }
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(5));
}

// Runs `call` while `closing` is requested 300 ms in: the status it ended with (OK: it threw
// none) and how long it took.
std::pair<grpc::StatusCode, std::chrono::steady_clock::duration> closed_during(
    std::stop_source& closing, const std::function<void()>& call) {
  std::thread closer([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    closing.request_stop();
  });
  const auto start = std::chrono::steady_clock::now();
  grpc::StatusCode code = grpc::StatusCode::OK;
  try {
    call();
  } catch (const StreamError& e) {
    code = e.code();
  }
  closer.join();
  return {code, std::chrono::steady_clock::now() - start};
}

// A client that closes while it opens a stream (stop requested) waits no longer, for the
// Welcome (kWelcomeWithin, 30 s) or for a connection to a server that is not there (5 s).
TEST_F(StreamClientTest, AClientClosingWhileItOpensAStreamWaitsNoLonger) {
  const std::string address = "127.0.0.1:" + std::to_string(port_);
  const auto opened_while_closing = [&](const v1::Hello& hello) {
    std::stop_source closing;
    return closed_during(closing, [&] {
      StreamClient client(connect(address), hello, StreamClient::kWelcomeWithin,
                          closing.get_token());
    });
  };
  v1::Hello mute;
  mute.set_token("mute");
  const auto [unwelcomed, waited_for_welcome] = opened_while_closing(mute);
  EXPECT_EQ(unwelcomed, grpc::StatusCode::CANCELLED);
  EXPECT_LT(waited_for_welcome, std::chrono::seconds(2));
  server_->Shutdown(std::chrono::system_clock::now());  // nobody listens there now
  server_.reset();
  const auto [unconnected, waited_for_connection] = opened_while_closing(v1::Hello{});
  EXPECT_EQ(unconnected, grpc::StatusCode::CANCELLED);
  EXPECT_LT(waited_for_connection, std::chrono::seconds(2));
}

// A client closing does not wait for a snapshot call the server never answers (its deadline is
// seconds, more for a large session over a slow link).
TEST_F(StreamClientTest, ASnapshotCallUnderWayWaitsNoLongerOnceTheClientCloses) {
  std::stop_source closing;
  StreamClient client(connect("127.0.0.1:" + std::to_string(port_)), v1::Hello{},
                      StreamClient::kWelcomeWithin, closing.get_token());
  const auto [code, waited] = closed_during(closing, [&] { client.snapshot(); });
  EXPECT_EQ(code, grpc::StatusCode::CANCELLED);
  EXPECT_LT(waited, std::chrono::seconds(2));
}

TEST_F(StreamClientTest, FinishingWithAServerThatNeverEndsTheStreamTakesBoundedTime) {
  StreamClient client(connect("127.0.0.1:" + std::to_string(port_)), v1::Hello{});
  v1::ClientMessage tilt;
  tilt.mutable_tilt()->set_y(-1.0f);
  for (int k = 0; k < 10; ++k) EXPECT_NE(client.send(tilt), 0u);
  const auto start = std::chrono::steady_clock::now();
  const grpc::Status status = client.finish();
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_LT(seconds, 2.0 * StreamClient::kFinishWithin.count() + 2.0);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::UNAVAILABLE);
  EXPECT_NE(status.error_message().find("did not end the stream"), std::string::npos)
      << status.error_message();
}

}  // namespace
}  // namespace fluidcast::client

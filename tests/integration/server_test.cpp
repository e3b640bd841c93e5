// The real server on loopback (lavapipe), driven by the real client library: its life (systemd,
// shutdown), handshake and frames, renderer fallback, idle sessions, keys, limits, and every bad
// input with its documented status while others stream on.
#include <grpcpp/generic/generic_stub.h>
#include <gtest/gtest.h>
#include <sys/socket.h>
#include <sys/un.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <thread>
#include <vector>

#include "fluidcast/codec/jpeg.h"
#include "server_test_support.h"

namespace fluidcast {
namespace {

// Under systemd's Type=notify: READY=1 once gRPC and HTTP listen, STOPPING=1 on SIGTERM.
TEST(ServerTest, TellsSystemdWhenReadyAndWhenStopping) {
  const std::filesystem::path path =
      std::filesystem::temp_directory_path() / ("fluidcast-notify-" + std::to_string(getpid()));
  const int socket_fd = socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  ASSERT_GE(socket_fd, 0);
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  std::snprintf(address.sun_path, sizeof address.sun_path, "%s", path.c_str());
  std::filesystem::remove(path);
  ASSERT_EQ(bind(socket_fd, reinterpret_cast<const sockaddr*>(&address), sizeof address), 0);
  const timeval wait{30, 0};
  setsockopt(socket_fd, SOL_SOCKET, SO_RCVTIMEO, &wait, sizeof wait);
  const auto next_notice = [&] {
    char text[512];
    const ssize_t size = recv(socket_fd, text, sizeof text, 0);
    return size > 0 ? std::string(text, std::size_t(size)) : std::string("(nothing within 30 s)");
  };

  setenv("NOTIFY_SOCKET", path.c_str(), 1);
  testing::ServerProcess server;
  unsetenv("NOTIFY_SOCKET");
  EXPECT_NE(next_notice().find("READY=1"), std::string::npos);
  EXPECT_EQ(server.stop(), 0);
  EXPECT_NE(next_notice().find("STOPPING=1"), std::string::npos);
  close(socket_fd);
  std::filesystem::remove(path);
}

TEST(ServerTest, HandshakeThenFramesThatDecodeAtTheRequestedSize) {
  testing::ServerProcess server;
  auto channel = client::connect(server.grpc_address());
  grpc::ClientContext context;
  v1::ServerInfo info;
  ASSERT_TRUE(v1::Fluidcast::NewStub(channel)->GetServerInfo(&context, {}, &info).ok());
  EXPECT_FALSE(info.device().empty());
  EXPECT_GT(info.rules().scenes_size(), 0);

  StreamClient stream(channel, small_hello());
  EXPECT_EQ(stream.welcome().session_id().size(), 32u);
  // The client builds its menus and clamps from the same table GetServerInfo gives.
  EXPECT_EQ(stream.welcome().rules().SerializeAsString(), info.rules().SerializeAsString());
  EXPECT_EQ(stream.welcome().rules().pointer_ids(), 16u);
  EXPECT_EQ(stream.welcome().state().particles(), 1000u);
  std::uint64_t last_sequence = 0;
  for (int k = 0; k < 3; ++k) {
    const v1::Frame frame = frame_from(stream);
    EXPECT_GT(frame.sequence(), last_sequence);
    last_sequence = frame.sequence();
    const auto image = codec::decode_jpeg(
        {reinterpret_cast<const std::uint8_t*>(frame.jpeg().data()), frame.jpeg().size()});
    EXPECT_EQ(image.width, 160);
    EXPECT_EQ(image.height, 120);
    EXPECT_EQ(frame.width(), 160u);
    EXPECT_GT(frame.timings().encode_ms(), 0.0f);
  }
  EXPECT_TRUE(stream.finish().ok());
  EXPECT_EQ(server.stop(), 0);
}

// On a device that cannot draw Marching Cubes (here lavapipe with independent blending left off),
// the server does not offer it, and a viewer that asks for it gets SSFR, as its frames say.
TEST(ServerTest, ARendererTheDeviceCannotDrawFallsBackToSsfr) {
  setenv("FLUIDCAST_INDEPENDENT_BLEND", "0", 1);
  testing::ServerProcess server;
  unsetenv("FLUIDCAST_INDEPENDENT_BLEND");
  auto channel = client::connect(server.grpc_address());
  grpc::ClientContext context;
  v1::ServerInfo info;
  ASSERT_TRUE(v1::Fluidcast::NewStub(channel)->GetServerInfo(&context, {}, &info).ok());
  EXPECT_EQ(
      std::vector<std::string>(info.rules().renderers().begin(), info.rules().renderers().end()),
      (std::vector<std::string>{"points", "ssfr", "auto"}));
  v1::Hello hello = small_hello();
  hello.mutable_quality()->set_renderer("mc");
  StreamClient stream(channel, hello);
  for (int k = 0; k < 2; ++k) EXPECT_EQ(frame_from(stream).renderer(), "ssfr");
  EXPECT_TRUE(stream.finish().ok());
  EXPECT_EQ(server.stop(), 0);
}

// A session nobody touches for --idle-timeout ends its streams with DEADLINE_EXCEEDED, and a
// resume goes on; a session whose viewer keeps touching it streams on; acks and a phone's
// unchanging tilt are not input.
TEST(ServerTest, AnUntouchedSessionIdlesOutAndATouchedOneStreamsOn) {
  testing::ServerProcess server({"--idle-timeout", "2"});
  const std::string& address = server.grpc_address();
  StreamClient idle(client::connect(address), small_hello());
  StreamClient busy(client::connect(address), small_hello());
  const auto start = std::chrono::steady_clock::now();
  while (std::chrono::steady_clock::now() - start < seconds(5) && !idle.ended()) {
    idle.tilt(0.0f, -9.81f, 0.0f);  // lying still
    idle.next_frame(milliseconds(100));
    busy.pointer(0, v1::PointerEvent::DOWN, 0.5f, 0.7f);
    busy.pointer(0, v1::PointerEvent::UP, 0.5f, 0.7f);
    busy.next_frame(milliseconds(100));
  }
  ASSERT_TRUE(idle.ended()) << "still streaming after 5 s without input";
  EXPECT_EQ(idle.status().error_code(), grpc::StatusCode::DEADLINE_EXCEEDED);
  EXPECT_NE(idle.status().error_message().find("--idle-timeout"), std::string::npos);
  EXPECT_FALSE(busy.ended()) << busy.status().error_message();
  frame_from(busy);

  v1::Hello resume = small_hello();
  resume.mutable_resume()->set_key(idle.welcome().access().resume_key());
  StreamClient resumed(client::connect(address), resume);
  EXPECT_EQ(resumed.welcome().session_id(), idle.welcome().session_id());
  // Touched until its first frame comes: on a loaded machine that may take longer than the idle
  // timeout.
  std::optional<v1::Frame> first;
  for (const auto give_up = std::chrono::steady_clock::now() + seconds(30);
       !first && !resumed.ended() && std::chrono::steady_clock::now() < give_up;) {
    resumed.pointer(0, v1::PointerEvent::DOWN, 0.5f, 0.7f);
    resumed.pointer(0, v1::PointerEvent::UP, 0.5f, 0.7f);
    first = resumed.next_frame(milliseconds(250));
  }
  EXPECT_TRUE(first) << resumed.status().error_message();
}

TEST(ServerTest, EveryBadInputEndsOnlyItsOwnStreamWithItsStatus) {
  // Each bad input's session waits out the resume grace: more than the per-address default.
  testing::ServerProcess server(
      {"--max-width", "640", "--max-height", "480", "--max-sessions-per-address", "8"});
  const std::string& address = server.grpc_address();
  StreamClient bystander(client::connect(address), small_hello());
  frame_from(bystander);

  v1::ClientMessage nan_pointer;
  nan_pointer.mutable_pointer()->set_phase(v1::PointerEvent::DOWN);
  nan_pointer.mutable_pointer()->set_x(std::numeric_limits<float>::quiet_NaN());
  EXPECT_EQ(status_after(address, nan_pointer).error_code(), grpc::StatusCode::INVALID_ARGUMENT);

  v1::ClientMessage outside;
  outside.mutable_pointer()->set_phase(v1::PointerEvent::MOVE);
  outside.mutable_pointer()->set_x(1.5f);
  EXPECT_EQ(status_after(address, outside).error_code(), grpc::StatusCode::INVALID_ARGUMENT);

  v1::ClientMessage second_hello;
  *second_hello.mutable_hello() = small_hello();
  EXPECT_EQ(status_after(address, second_hello).error_code(),
            grpc::StatusCode::FAILED_PRECONDITION);

  v1::ClientMessage empty;
  EXPECT_EQ(status_after(address, empty).error_code(), grpc::StatusCode::INVALID_ARGUMENT);

  // gRPC takes messages as large as a snapshot; a stream's are at most a Hello with the largest
  // state (448 KiB).
  v1::ClientMessage padded;
  padded.mutable_tilt()->set_y(-9.81f);
  padded.GetReflection()->MutableUnknownFields(&padded)->AddLengthDelimited(
      1000, std::string(1 << 20, 'x'));
  EXPECT_EQ(status_after(address, padded).error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);

  v1::Hello unknown = small_hello();
  unknown.set_join("0123456789abcdef0123456789abcdef");
  EXPECT_EQ(refusal_of(address, unknown), grpc::StatusCode::NOT_FOUND);

  v1::Hello too_fast = small_hello();  // past the server's --max-fps
  too_fast.mutable_quality()->set_max_fps(1000);
  EXPECT_EQ(refusal_of(address, too_fast), grpc::StatusCode::RESOURCE_EXHAUSTED);

  v1::Hello bad_scene = small_hello();
  bad_scene.mutable_create()->set_scene("ocean");
  EXPECT_EQ(refusal_of(address, bad_scene), grpc::StatusCode::INVALID_ARGUMENT);

  {  // A first message that is not a Hello.
    auto stub = v1::Fluidcast::NewStub(client::connect(address));
    grpc::ClientContext context;
    auto stream = stub->Stream(&context);
    v1::ClientMessage tilt;
    tilt.mutable_tilt()->set_y(-9.81f);
    stream->Write(tilt);
    v1::ServerMessage reply;
    EXPECT_FALSE(stream->Read(&reply));
    EXPECT_EQ(stream->Finish().error_code(), grpc::StatusCode::FAILED_PRECONDITION);
  }

  {  // Bytes that are not a ClientMessage at all.
    grpc::GenericStub generic(client::connect(address));
    grpc::CompletionQueue queue;
    grpc::ClientContext context;
    const auto done = [&queue] {
      void* tag = nullptr;
      bool ok = false;
      queue.Next(&tag, &ok);
      return ok;
    };
    auto call = generic.PrepareCall(&context, "/fluidcast.v1.Fluidcast/Stream", &queue);
    call->StartCall(nullptr);
    ASSERT_TRUE(done());
    grpc::Slice garbage(std::string("\xff\xff\xff"));
    call->Write(grpc::ByteBuffer(&garbage, 1), nullptr);
    done();
    grpc::ByteBuffer reply;
    call->Read(&reply, nullptr);
    EXPECT_FALSE(done());
    grpc::Status status;
    call->Finish(&status, nullptr);
    done();
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
    EXPECT_NE(status.error_message().find("not a fluidcast.v1.ClientMessage"), std::string::npos)
        << status.error_message();
  }

  // The bystander streamed through all of it.
  EXPECT_FALSE(bystander.ended());
  frame_from(bystander);
  frame_from(bystander);
}

TEST(ServerTest, LimitsAndTokensAreEnforcedWithTheirStatus) {
  const auto token_file = std::filesystem::temp_directory_path() / "fluidcast_test_token";
  std::ofstream(token_file) << "open sesame\r\n";  // written on Windows: the \r is no part of it
  testing::ServerProcess server(
      {"--max-sessions", "1", "--token-file", token_file.string(), "--max-input-rate", "50"});
  const std::string& address = server.grpc_address();
  v1::Hello hello = small_hello();
  EXPECT_EQ(refusal_of(address, hello), grpc::StatusCode::UNAUTHENTICATED);
  hello.set_token("wrong");
  EXPECT_EQ(refusal_of(address, hello), grpc::StatusCode::UNAUTHENTICATED);
  hello.set_token("open sesame");
  StreamClient first(client::connect(address), hello);
  EXPECT_EQ(refusal_of(address, hello), grpc::StatusCode::RESOURCE_EXHAUSTED);  // one session

  // An input flood beyond 50 events a second ends the stream.
  for (int k = 0; k < 200 && !first.ended(); ++k) {
    first.pointer(0, v1::PointerEvent::MOVE, 0.5f, 0.5f);
  }
  for (int k = 0; k < 100 && !first.ended(); ++k) first.next_frame(milliseconds(100));
  ASSERT_TRUE(first.ended());
  EXPECT_EQ(first.status().error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  std::filesystem::remove(token_file);
}

// The session's keys open what they say: the view key watches, the control key plays, a resume
// key brings back its own viewer once; the session id and viewer ids open nothing.
TEST(ServerTest, KeysOpenWhatTheySayAndIdsOpenNothing) {
  testing::ServerProcess server;
  const std::string& address = server.grpc_address();
  StreamClient creator(client::connect(address), small_hello());
  const v1::Access& keys = creator.welcome().access();
  EXPECT_TRUE(keys.control());
  for (const std::string& key : {keys.view_key(), keys.control_key(), keys.resume_key()}) {
    EXPECT_EQ(key.size(), 32u);
    EXPECT_NE(key, creator.welcome().session_id());
  }
  EXPECT_NE(keys.view_key(), keys.control_key());

  v1::Hello by_id = small_hello();
  by_id.set_join(creator.welcome().session_id());
  EXPECT_EQ(refusal_of(address, by_id), grpc::StatusCode::NOT_FOUND);
  v1::Hello resume_by_view_key = small_hello();
  resume_by_view_key.mutable_resume()->set_key(keys.view_key());
  EXPECT_EQ(refusal_of(address, resume_by_view_key), grpc::StatusCode::NOT_FOUND);

  v1::Hello watch = small_hello();
  watch.set_join(keys.view_key());
  StreamClient watcher(client::connect(address), watch);
  EXPECT_FALSE(watcher.welcome().access().control());
  EXPECT_TRUE(watcher.welcome().access().control_key().empty());
  EXPECT_EQ(watcher.welcome().access().view_key(), keys.view_key());
  // Its pointers orbit its own camera: the stream goes on.
  watcher.pointer(0, v1::PointerEvent::DOWN, 0.5f, 0.7f);
  watcher.pointer(0, v1::PointerEvent::MOVE, 0.6f, 0.7f);
  watcher.pointer(0, v1::PointerEvent::UP, 0.6f, 0.7f);
  frame_from(watcher);
  EXPECT_FALSE(watcher.ended()) << watcher.status().error_message();

  auto stub = v1::Fluidcast::NewStub(client::connect(address));
  v1::PutSnapshotRequest put;
  put.set_key(keys.view_key());
  *put.mutable_snapshot() = watcher.snapshot();
  v1::PutSnapshotReply reply;
  {
    grpc::ClientContext context;
    const grpc::Status status = stub->PutSnapshot(&context, put, &reply);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::PERMISSION_DENIED) << status.error_message();
  }
  put.set_key(keys.control_key());
  {
    grpc::ClientContext context;
    EXPECT_TRUE(stub->PutSnapshot(&context, put, &reply).ok());
  }

  v1::Hello play = small_hello();
  play.set_join(keys.control_key());
  StreamClient player(client::connect(address), play);
  EXPECT_TRUE(player.welcome().access().control());
  EXPECT_EQ(player.welcome().access().control_key(), keys.control_key());

  // A view-only viewer that tilts ends alone, told why; the others stream on.
  watcher.send_raw([] {
    v1::ClientMessage tilt;
    tilt.mutable_tilt()->set_y(-9.81f);
    return tilt;
  }());
  for (int k = 0; k < 300 && !watcher.ended(); ++k) watcher.next_frame(milliseconds(100));
  EXPECT_EQ(watcher.status().error_code(), grpc::StatusCode::PERMISSION_DENIED);
  EXPECT_NE(watcher.status().error_message().find("control key"), std::string::npos)
      << watcher.status().error_message();
  frame_from(creator);
  frame_from(player);

  // A resume key works once: the viewer that comes back gets a new one.
  const std::string resume_key = player.welcome().access().resume_key();
  player.drop();
  v1::Hello resume = small_hello();
  resume.mutable_resume()->set_key(resume_key);
  StreamClient back(client::connect(address), resume);
  EXPECT_TRUE(back.welcome().access().control());
  EXPECT_EQ(refusal_of(address, resume), grpc::StatusCode::NOT_FOUND);
  frame_from(back);
}

// One address holds at most its share of the sessions (half by default), those waiting for a
// resume included; a client that says goodbye frees its slot at once and cannot resume.
TEST(ServerTest, OneAddressHoldsItsShareOfSessionsAndAGoodbyeFreesASlot) {
  testing::ServerProcess server({"--max-sessions", "4"});
  const std::string& address = server.grpc_address();
  auto first = std::make_unique<StreamClient>(client::connect(address), small_hello());
  auto second = std::make_unique<StreamClient>(client::connect(address), small_hello());
  EXPECT_EQ(first->welcome().limits().max_sessions_per_address(), 2u);
  try {
    StreamClient third(client::connect(address), small_hello());
    ADD_FAILURE() << "a third session from one address";
  } catch (const StreamError& e) {
    EXPECT_EQ(e.code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
    EXPECT_NE(std::string(e.what()).find("--max-sessions-per-address"), std::string::npos)
        << e.what();
  }

  v1::Hello resume = small_hello();
  resume.mutable_resume()->set_key(first->welcome().access().resume_key());
  EXPECT_TRUE(first->finish().ok());  // goodbye
  first.reset();
  std::unique_ptr<StreamClient> third;
  for (int k = 0; k < 50 && !third; ++k) {  // the slot is freed at the next tick
    try {
      third = std::make_unique<StreamClient>(client::connect(address), small_hello());
    } catch (const StreamError& e) {
      ASSERT_EQ(e.code(), grpc::StatusCode::RESOURCE_EXHAUSTED) << e.what();
      std::this_thread::sleep_for(milliseconds(100));
    }
  }
  ASSERT_TRUE(third) << "the slot of a client that said goodbye was not freed within 5 s";
  EXPECT_EQ(refusal_of(address, resume), grpc::StatusCode::NOT_FOUND);

  // A dropped connection keeps its session for a resume, and its slot with it.
  second->drop();
  second.reset();
  std::this_thread::sleep_for(milliseconds(500));
  EXPECT_EQ(refusal_of(address, small_hello()), grpc::StatusCode::RESOURCE_EXHAUSTED);
}

TEST(ServerTest, ShutdownEndsEveryStreamWithUnavailableAndExitsZero) {
  testing::ServerProcess server;
  StreamClient stream(client::connect(server.grpc_address()), small_hello());
  frame_from(stream);
  EXPECT_EQ(server.stop(), 0);
  for (int k = 0; k < 100 && !stream.ended(); ++k) stream.next_frame(milliseconds(100));
  ASSERT_TRUE(stream.ended());
  EXPECT_EQ(stream.status().error_code(), grpc::StatusCode::UNAVAILABLE);
}

// Connections that wait for their client hold nothing up: one silent, one midway through a TLS
// handshake (a ClientHello's record header and the start of its message, past the server's
// telling TLS from HTTP), one midway through a request. Those answering a request or holding a
// WebSocket are given 1 s to finish; these are cut at once (SIGTERM to exit: 50–80 ms measured
// with them and without, on two busy cores).
TEST(ServerTest, ConnectionsWaitingForTheirClientDoNotHoldUpShutdown) {
  testing::ServerProcess server;
  testing::RawConnection silent(server.http_port()), handshaking(server.http_port()),
      requesting(server.http_port());
  ASSERT_TRUE(silent.connected());
  ASSERT_TRUE(handshaking.send_bytes(std::string("\x16\x03\x01\x02\x00\x01\x00\x01\xfc", 9)));
  ASSERT_TRUE(requesting.send_bytes("GET /healthz HTTP/1.1\r\nHost: 127.0.0.1\r\n"));
  std::this_thread::sleep_for(milliseconds(300));  // read by the server: it waits for the rest
  const auto stopping = std::chrono::steady_clock::now();
  EXPECT_EQ(server.stop(), 0);
  EXPECT_LT(std::chrono::steady_clock::now() - stopping, milliseconds(900))
      << "a connection waiting for its client was waited for";
}

}  // namespace
}  // namespace fluidcast

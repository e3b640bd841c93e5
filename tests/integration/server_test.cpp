// The real server on loopback (lavapipe), driven by the real client library: handshake, frames,
// sessions, interaction, and every bad input with its documented status while others stream on.
#include <grpcpp/generic/generic_stub.h>
#include <gtest/gtest.h>
#include <sys/socket.h>
#include <sys/un.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <thread>
#include <vector>

#include "fluidcast/codec/jpeg.h"
#include "server_process.h"
#include "stream_client.h"

namespace fluidcast {
namespace {

using client::StreamClient;
using client::StreamError;
using std::chrono::milliseconds;
using std::chrono::seconds;

// Small enough for two cores: a fast session, a small frame.
v1::Hello small_hello(std::uint32_t particles = 1000) {
  v1::Hello hello;
  hello.mutable_viewport()->set_width(160);
  hello.mutable_viewport()->set_height(120);
  hello.mutable_create()->set_scene("dam_break");
  hello.mutable_create()->set_particles(particles);
  return hello;
}

v1::Frame frame_from(StreamClient& stream) {
  auto frame = stream.next_frame(seconds(30));
  if (!frame) throw std::runtime_error("no frame within 30 s: " + stream.status().error_message());
  return *frame;
}

// Sends one message after a valid Hello, and returns how the server ended the stream.
grpc::Status status_after(const std::string& address, const v1::ClientMessage& message) {
  StreamClient stream(client::connect(address), small_hello());
  stream.send_raw(message);
  for (int k = 0; k < 300 && !stream.ended(); ++k) stream.next_frame(milliseconds(100));
  return stream.ended() ? stream.status() : grpc::Status(grpc::StatusCode::OK, "still streaming");
}

grpc::StatusCode refusal_of(const std::string& address, const v1::Hello& hello) {
  try {
    StreamClient stream(client::connect(address), hello);
  } catch (const StreamError& e) {
    std::printf("refused: %s\n", e.what());
    return e.code();
  }
  return grpc::StatusCode::OK;
}

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

// A client keeps its session's state (StateRequest) and hands it back in a new session
// (NewSession.state), which goes on from it: what the page does across a dropped network.
TEST(ServerTest, AStreamCarriesTheStateBothWays) {
  testing::ServerProcess server;
  auto channel = client::connect(server.grpc_address());
  StreamClient first(channel, small_hello(800));
  for (int k = 0; k < 5; ++k) frame_from(first);
  v1::ClientMessage request;
  request.mutable_state_request();
  ASSERT_TRUE(first.send_raw(request));
  const auto state = first.take_state(seconds(30));
  ASSERT_TRUE(state) << first.status().error_message();
  EXPECT_EQ(state->positions_size(), 3 * 800);
  EXPECT_EQ(state->velocities_size(), 3 * 800);
  EXPECT_EQ(state->scene(), "dam_break");
  EXPECT_GT(state->time(), 0.0);

  v1::Hello hello = small_hello(100);  // the state's count wins
  hello.mutable_create()->set_scene("pool");
  *hello.mutable_create()->mutable_state() = *state;
  StreamClient second(channel, hello);
  EXPECT_EQ(second.welcome().state().particles(), 800u);
  EXPECT_EQ(second.welcome().state().scene(), "dam_break");
  EXPECT_GE(frame_from(second).sim_time(), state->time());

  // Its rules: a state outside the tank, and more than a stream carries, are refused.
  v1::Hello outside = hello;
  outside.mutable_create()->mutable_state()->set_positions(1, -5.0f);
  EXPECT_EQ(refusal_of(server.grpc_address(), outside), grpc::StatusCode::INVALID_ARGUMENT);
  v1::Hello huge = hello;
  v1::Snapshot& big = *huge.mutable_create()->mutable_state();
  while (big.positions_size() / 3 <= int(second.welcome().rules().max_state_particles())) {
    for (int axis = 0; axis < 3; ++axis) {
      big.add_positions(state->positions(axis));
      big.add_velocities(0.0f);
    }
  }
  EXPECT_EQ(refusal_of(server.grpc_address(), huge), grpc::StatusCode::RESOURCE_EXHAUSTED);
  // Asked too often, the stream ends; the other goes on.
  for (int k = 0; k < 10 && !first.ended(); ++k) first.send_raw(request);
  for (int k = 0; k < 300 && !first.ended(); ++k) first.next_frame(milliseconds(100));
  EXPECT_EQ(first.status().error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  frame_from(second);
  EXPECT_TRUE(second.finish().ok());
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

// On a device that cannot draw the fluid renderers (here lavapipe with independent blending left
// off), the server offers points only, and a viewer that asks for SSFR gets points, as its frames
// say.
TEST(ServerTest, ARendererTheDeviceCannotDrawFallsBackToPoints) {
  setenv("FLUIDCAST_INDEPENDENT_BLEND", "0", 1);
  testing::ServerProcess server;
  unsetenv("FLUIDCAST_INDEPENDENT_BLEND");
  auto channel = client::connect(server.grpc_address());
  grpc::ClientContext context;
  v1::ServerInfo info;
  ASSERT_TRUE(v1::Fluidcast::NewStub(channel)->GetServerInfo(&context, {}, &info).ok());
  EXPECT_EQ(
      std::vector<std::string>(info.rules().renderers().begin(), info.rules().renderers().end()),
      (std::vector<std::string>{"points", "auto"}));
  v1::Hello hello = small_hello();
  hello.mutable_quality()->set_renderer("ssfr");
  StreamClient stream(channel, hello);
  for (int k = 0; k < 2; ++k) EXPECT_EQ(frame_from(stream).renderer(), "points");
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
  frame_from(resumed);
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

  v1::Hello unknown = small_hello();
  unknown.set_join("0123456789abcdef0123456789abcdef");
  EXPECT_EQ(refusal_of(address, unknown), grpc::StatusCode::NOT_FOUND);

  v1::Hello huge = small_hello();
  huge.mutable_viewport()->set_width(4000);
  EXPECT_EQ(refusal_of(address, huge), grpc::StatusCode::RESOURCE_EXHAUSTED);

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

TEST(ServerTest, TwoViewersShareASessionAndResumeFindsTheFluidAsItWas) {
  testing::ServerProcess server;
  const std::string& address = server.grpc_address();
  auto first = std::make_unique<StreamClient>(client::connect(address), small_hello());
  const std::string session = first->welcome().session_id();
  v1::Hello join = small_hello();
  join.set_join(first->welcome().access().view_key());
  StreamClient second(client::connect(address), join);
  EXPECT_EQ(second.welcome().session_id(), session);
  EXPECT_NE(second.welcome().viewer_id(), first->welcome().viewer_id());
  frame_from(second);
  double time_before = 0.0;
  for (int k = 0; k < 3; ++k) time_before = frame_from(*first).sim_time();
  const v1::Access access = first->welcome().access();
  first->drop();  // the network goes away
  first.reset();

  v1::Hello resume = small_hello();
  resume.mutable_resume()->set_key(access.resume_key());
  StreamClient back(client::connect(address), resume);
  EXPECT_EQ(back.welcome().session_id(), session);
  EXPECT_TRUE(back.welcome().access().control()) << "the creator came back as a viewer";
  EXPECT_NE(back.welcome().access().resume_key(), access.resume_key());
  // Not a new fluid: time went on from where it was.
  EXPECT_GE(frame_from(back).sim_time(), time_before);
}

v1::Snapshot snapshot_of(const std::string& address, const v1::Welcome& welcome) {
  auto stub = v1::Fluidcast::NewStub(client::connect(address));
  grpc::ClientContext context;
  v1::SnapshotRequest request;
  request.set_key(welcome.access().view_key());
  v1::Snapshot snapshot;
  const grpc::Status status = stub->GetSnapshot(&context, request, &snapshot);
  if (!status.ok()) throw StreamError(status);
  return snapshot;
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
  *put.mutable_snapshot() = snapshot_of(address, watcher.welcome());
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

TEST(ServerTest, TiltTurnsGravity) {
  testing::ServerProcess server;
  StreamClient stream(client::connect(server.grpc_address()), small_hello());
  frame_from(stream);
  stream.tilt(9.81f, 0.0f, 0.0f);  // the device's right is down
  // Wait for a frame that reflects the tilt.
  const std::uint64_t tilt_event = 1;
  for (int k = 0; k < 100; ++k) {
    if (frame_from(stream).input_event_id() >= tilt_event) break;
  }
  auto stub = v1::Fluidcast::NewStub(client::connect(server.grpc_address()));
  grpc::ClientContext context;
  v1::SnapshotRequest request;
  request.set_key(stream.welcome().access().view_key());
  v1::Snapshot snapshot;
  ASSERT_TRUE(stub->GetSnapshot(&context, request, &snapshot).ok());
  const v1::Vec3& g = snapshot.gravity();
  EXPECT_NEAR(std::sqrt(g.x() * g.x() + g.y() * g.y() + g.z() * g.z()), 9.81f, 1e-3f);
  EXPECT_NEAR(g.y(), 0.0f, 1e-3f);  // the camera's right is horizontal
  EXPECT_EQ(snapshot.positions_size(), 3 * 1000);
}

// Mean speed of the particles within `radius` of `centre` (x and z only: a column), m/s.
double mean_speed_near(const v1::Snapshot& snapshot, float x, float radius) {
  double sum = 0.0;
  int count = 0;
  for (int k = 0; k < snapshot.positions_size() / 3; ++k) {
    if (std::abs(snapshot.positions(3 * k) - x) > radius) continue;
    const float vx = snapshot.velocities(3 * k), vy = snapshot.velocities(3 * k + 1),
                vz = snapshot.velocities(3 * k + 2);
    sum += std::sqrt(vx * vx + vy * vy + vz * vz);
    ++count;
  }
  return count > 0 ? sum / count : 0.0;
}

// A pool at rest, looked at from the front: a finger swept through the middle of the frame
// stirs the water there, and the same pool left alone stays calm.
TEST(ServerTest, ADragStirsTheFluidWhereItTouches) {
  testing::ServerProcess server;
  const std::string& address = server.grpc_address();
  v1::Hello hello = small_hello(2000);
  hello.mutable_create()->set_scene("pool");
  StreamClient touched(client::connect(address), hello);
  StreamClient calm(client::connect(address), hello);
  frame_from(touched);
  frame_from(calm);
  // The camera looks at the tank's centre, the whole tank in the frame; the water fills its lower
  // 30 %: touch well below the middle.
  touched.pointer(0, v1::PointerEvent::DOWN, 0.45f, 0.7f);
  for (int k = 0; k < 20; ++k) {
    frame_from(touched);
    frame_from(calm);
    touched.pointer(0, v1::PointerEvent::MOVE, 0.45f + 0.01f * float(k % 10), 0.7f);
  }
  const v1::Snapshot stirred = snapshot_of(address, touched.welcome());
  const v1::Snapshot still = snapshot_of(address, calm.welcome());
  const float centre_x = 0.5f * (touched.welcome().state().tank().min().x() +
                                 touched.welcome().state().tank().max().x());
  const double stirred_speed = mean_speed_near(stirred, centre_x, 0.3f);
  const double still_speed = mean_speed_near(still, centre_x, 0.3f);
  std::printf("mean speed near the finger: %.3f m/s stirred, %.3f m/s left alone\n", stirred_speed,
              still_speed);
  EXPECT_GT(stirred_speed, 3.0 * still_speed + 0.02);
}

// A fluid moves from one session to another (what a client's handoff does): particles, gravity
// and clock; a snapshot with a NaN is refused and leaves the session as it was.
TEST(ServerTest, SnapshotsMoveAFluidBetweenSessionsAndBadOnesChangeNothing) {
  testing::ServerProcess server;
  const std::string& address = server.grpc_address();
  StreamClient from(client::connect(address), small_hello(800));
  StreamClient into(client::connect(address), small_hello(1000));
  for (int k = 0; k < 5; ++k) frame_from(from);
  from.tilt(3.0f, -9.0f, 0.0f);
  for (int k = 0; k < 5; ++k) frame_from(from);
  const v1::Snapshot moved = snapshot_of(address, from.welcome());
  EXPECT_GT(moved.time(), 0.0);

  auto stub = v1::Fluidcast::NewStub(client::connect(address));
  v1::PutSnapshotRequest put;
  put.set_key(into.welcome().access().control_key());
  *put.mutable_snapshot() = moved;
  v1::PutSnapshotReply reply;
  {
    grpc::ClientContext context;
    ASSERT_TRUE(stub->PutSnapshot(&context, put, &reply).ok());
  }
  EXPECT_EQ(reply.particles(), 800u);
  const v1::Snapshot landed = snapshot_of(address, into.welcome());
  EXPECT_EQ(landed.positions_size(), 3 * 800);
  EXPECT_GE(landed.time(), moved.time());
  EXPECT_NEAR(landed.gravity().x(), moved.gravity().x(), 1e-4f);

  put.mutable_snapshot()->set_positions(7, std::numeric_limits<float>::quiet_NaN());
  {
    grpc::ClientContext context;
    EXPECT_EQ(stub->PutSnapshot(&context, put, &reply).error_code(),
              grpc::StatusCode::INVALID_ARGUMENT);
  }
  EXPECT_EQ(snapshot_of(address, into.welcome()).positions_size(), 3 * 800);

  // A key too long to be one is refused without being echoed back.
  {
    grpc::ClientContext context;
    v1::SnapshotRequest request;
    request.set_key(std::string(100000, 'x'));
    v1::Snapshot ignored;
    const grpc::Status status = stub->GetSnapshot(&context, request, &ignored);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
    EXPECT_LT(status.error_message().size(), 200u) << status.error_message().substr(0, 200);
  }

  // Every particle at the tank's centre, at rest: inside the tank and slow, but no fluid; it
  // would cost N² a step and never separate.
  *put.mutable_snapshot() = moved;
  for (int k = 0; k < put.snapshot().positions_size(); ++k) {
    put.mutable_snapshot()->set_positions(k, k % 3 == 1 ? 0.3f : k % 3 == 0 ? 0.8f : 0.15f);
  }
  {
    grpc::ClientContext context;
    const grpc::Status status = stub->PutSnapshot(&context, put, &reply);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
    EXPECT_NE(status.error_message().find("rest density"), std::string::npos)
        << status.error_message();
  }
  EXPECT_EQ(snapshot_of(address, into.welcome()).positions_size(), 3 * 800);
}

// A client that acknowledges frames it never reads (it learns their numbers from the server's
// metrics: the only viewer's frames are numbered 1, 2, 3…): flow control sees a viewer keeping up,
// so only the transport's rule — frames wait in the server at most one behind the one being
// written — keeps the server's memory bounded while the session goes on rendering large frames.
TEST(ServerTest, AClientThatStopsReadingDoesNotGrowTheServersMemory) {
  testing::ServerProcess server;
  auto stub = v1::Fluidcast::NewStub(client::connect(server.grpc_address()));
  grpc::ClientContext context;
  auto stream = stub->Stream(&context);
  v1::ClientMessage message;
  *message.mutable_hello() = small_hello();
  message.mutable_hello()->mutable_viewport()->set_width(640);
  message.mutable_hello()->mutable_viewport()->set_height(480);
  message.mutable_hello()->mutable_quality()->set_jpeg_quality(100);
  message.mutable_hello()->mutable_create()->set_scene("drop");
  ASSERT_TRUE(stream->Write(message));
  std::uint64_t acknowledged = 0;
  const auto acknowledge_for = [&](std::chrono::milliseconds span) {
    const auto end = std::chrono::steady_clock::now() + span;
    while (std::chrono::steady_clock::now() < end) {
      const auto sent = static_cast<std::uint64_t>(server.metric("fluidcast_frames_sent_total"));
      if (sent > acknowledged) {
        v1::ClientMessage ack;
        ack.mutable_ack()->set_sequence(acknowledged = sent);
        if (!stream->Write(ack)) return;
      }
      std::this_thread::sleep_for(milliseconds(100));
    }
  };
  acknowledge_for(seconds(3));  // the transport's windows fill
  const long before = server.resident_kb();
  acknowledge_for(seconds(6));
  const long after = server.resident_kb();
  const double dropped = server.metric("fluidcast_frames_dropped_total");
  std::printf(
      "server resident memory: %ld kB, then %ld kB 6 s later (%llu frames acknowledged, "
      "%.0f frames dropped unread)\n",
      before, after, static_cast<unsigned long long>(acknowledged), dropped);
  EXPECT_GT(dropped, 0);  // the rule under test acted: else flow control alone held the memory
  // Six seconds at 30 frames a second of ~100 kB JPEGs would be ~18 MB if queued.
  EXPECT_LT(after - before, 4 * 1024);
  context.TryCancel();
}

// The protocol allows a session of one particle: the few that fill no tank make a droplet.
TEST(ServerTest, ASessionOfOneToAFewParticlesStreams) {
  testing::ServerProcess server;
  for (std::uint32_t particles : {1u, 2u, 3u, 7u}) {
    StreamClient stream(client::connect(server.grpc_address()), small_hello(particles));
    EXPECT_EQ(stream.welcome().state().particles(), particles);
    frame_from(stream);
    EXPECT_TRUE(stream.finish().ok());
  }
}

// A viewer that never acknowledges is throttled like one that falls behind: three frames, then
// one a second; it still sees the fluid.
TEST(ServerTest, AViewerThatNeverAcknowledgesIsThrottled) {
  testing::ServerProcess server;
  auto stub = v1::Fluidcast::NewStub(client::connect(server.grpc_address()));
  grpc::ClientContext context;
  auto stream = stub->Stream(&context);
  v1::ClientMessage message;
  *message.mutable_hello() = small_hello();
  message.mutable_hello()->mutable_quality()->set_max_fps(60);
  ASSERT_TRUE(stream->Write(message));
  v1::ServerMessage received;
  ASSERT_TRUE(stream->Read(&received));
  ASSERT_TRUE(received.has_welcome());
  int frames = 0;
  std::thread stop([&] {
    std::this_thread::sleep_for(seconds(4));
    context.TryCancel();
  });
  while (stream->Read(&received)) frames += received.has_frame();
  stop.join();
  std::printf("frames in 4 s without acknowledgements: %d\n", frames);
  EXPECT_GE(frames, 4);   // three, then one a second
  EXPECT_LE(frames, 10);  // not the 30 or 60 a second of a viewer that acknowledges
}

// A client that keeps resizing its viewport gets a new frame size at most four times a second
// (the newest size winning): each one is a new renderer on the shared worker.
TEST(ServerTest, ResizesAreCoalescedToAFewASecond) {
  testing::ServerProcess server;
  StreamClient stream(client::connect(server.grpc_address()), small_hello());
  frame_from(stream);
  int changes = 0;
  std::uint32_t width = 0;
  const auto start = std::chrono::steady_clock::now();
  for (int k = 0; std::chrono::steady_clock::now() - start < seconds(3); ++k) {
    v1::Command resize;
    resize.mutable_viewport()->set_width(k % 2 ? 320 : 160);
    resize.mutable_viewport()->set_height(k % 2 ? 240 : 120);
    stream.command(resize);
    while (const auto frame = stream.next_frame(milliseconds(0))) {
      changes += width != 0 && frame->width() != width;
      width = frame->width();
    }
    std::this_thread::sleep_for(milliseconds(20));  // 50 resizes a second
  }
  std::printf("frame size changes in 3 s of 50 resizes a second: %d\n", changes);
  EXPECT_GE(changes, 2);
  EXPECT_LE(changes, 3 * 4 + 1);
  EXPECT_FALSE(stream.ended()) << stream.status().error_message();
}

// An adaptive viewer whose acknowledgements come late (a slow network): the server lowers JPEG
// quality first, then the frame size; a viewer that keeps up keeps what it asked for.
TEST(ServerTest, AdaptiveQualityFallsForAViewerThatFallsBehind) {
  testing::ServerProcess server;
  auto stub = v1::Fluidcast::NewStub(client::connect(server.grpc_address()));
  grpc::ClientContext context;
  auto stream = stub->Stream(&context);
  v1::ClientMessage hello;
  *hello.mutable_hello() = small_hello();
  hello.mutable_hello()->mutable_quality()->set_adaptive(true);
  hello.mutable_hello()->mutable_quality()->set_jpeg_quality(80);
  hello.mutable_hello()->mutable_viewport()->set_width(320);
  hello.mutable_hello()->mutable_viewport()->set_height(240);
  ASSERT_TRUE(stream->Write(hello));
  v1::ServerMessage message;
  ASSERT_TRUE(stream->Read(&message));
  ASSERT_TRUE(message.has_welcome());
  std::uint32_t lowest_quality = 100, narrowest = 1000;
  for (int k = 0; k < 40 && stream->Read(&message); ++k) {
    lowest_quality = std::min(lowest_quality, message.frame().jpeg_quality());
    narrowest = std::min(narrowest, message.frame().width());
    std::this_thread::sleep_for(milliseconds(200));  // the acknowledgement is late
    v1::ClientMessage ack;
    ack.mutable_ack()->set_sequence(message.frame().sequence());
    stream->Write(ack);
  }
  std::printf("late acknowledgements: quality down to %u, width down to %u\n", lowest_quality,
              narrowest);
  EXPECT_LT(lowest_quality, 80u);
  EXPECT_LT(narrowest, 320u);
  context.TryCancel();

  // A viewer that acknowledges at once is never pushed to the floor (a loaded machine may still
  // trim its quality a little: the round trip includes the server's own queues).
  StreamClient keeping_up(client::connect(server.grpc_address()), *hello.mutable_hello());
  for (int k = 0; k < 6; ++k) {
    const v1::Frame frame = frame_from(keeping_up);
    EXPECT_EQ(frame.width(), 320u);
    EXPECT_GT(frame.jpeg_quality(), lowest_quality);
  }
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

}  // namespace
}  // namespace fluidcast

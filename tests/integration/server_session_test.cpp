// A session's fluid and its viewers on the real server (lavapipe): state and snapshots moved
// between sessions (and snapshot answers a client leaves unread), viewers sharing and resuming,
// tilt and drag, tiny sessions, and what flow control does for a viewer that stops reading, never
// acknowledges, resizes or falls behind, and a frame size that finds no GPU memory.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <future>
#include <limits>
#include <memory>
#include <set>
#include <string>
#include <thread>
#include <tuple>
#include <utility>

#include "fluidcast/codec/jpeg.h"
#include "server_test_support.h"
#include "session/server_limits.h"

namespace fluidcast {
namespace {

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

  // Its rules: a state outside the tank, squeezed past its rest density, or more than a stream
  // carries, is refused.
  v1::Hello outside = hello;
  outside.mutable_create()->mutable_state()->set_positions(1, -5.0f);
  EXPECT_EQ(refusal_of(server.grpc_address(), outside), grpc::StatusCode::INVALID_ARGUMENT);
  v1::Hello squeezed = hello;
  for (int k = 0; k < state->positions_size(); ++k) {
    squeezed.mutable_create()->mutable_state()->set_positions(k, state->positions(k % 3));
  }
  try {
    StreamClient refused(channel, squeezed);
    ADD_FAILURE() << "a squeezed state was taken";
  } catch (const StreamError& e) {
    EXPECT_EQ(e.code(), grpc::StatusCode::INVALID_ARGUMENT);
    EXPECT_NE(std::string(e.what()).find("rest density"), std::string::npos) << e.what();
  }
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

// A state is spaced for its scene's water and its count: put into a session of another scene or
// count, the session takes its scene, solver and count (its particles keep their rest density),
// as a new session given it does (NewSession.state). A name no scene has is refused, and the
// fluid stays.
TEST(ServerTest, ASnapshotOfAnotherSceneOrCountRebuildsTheSessionForIt) {
  testing::ServerProcess server;
  const std::string& address = server.grpc_address();
  v1::Hello pool = small_hello(800);
  pool.mutable_create()->set_scene("pool");
  StreamClient from(client::connect(address), pool);
  StreamClient into(client::connect(address), small_hello(1000));
  frame_from(from);
  frame_from(into);
  const float pool_spacing = from.welcome().state().particle_spacing();
  const float dam_break_spacing = into.welcome().state().particle_spacing();
  ASSERT_GT(std::abs(pool_spacing - dam_break_spacing), 1e-4f);
  const v1::Snapshot own = into.snapshot();

  auto stub = v1::Fluidcast::NewStub(client::connect(address));
  const auto put = [&](const v1::Snapshot& snapshot) {
    v1::PutSnapshotRequest request;
    request.set_key(into.welcome().access().control_key());
    *request.mutable_snapshot() = snapshot;
    v1::PutSnapshotReply reply;
    grpc::ClientContext context;
    return stub->PutSnapshot(&context, request, &reply);
  };
  // What a viewer joining now is told of the session.
  const auto joined = [&] {
    v1::Hello join = small_hello();
    join.set_join(into.welcome().access().view_key());
    StreamClient watcher(client::connect(address), join);
    return watcher.welcome().state();
  };

  v1::Snapshot poured = from.snapshot();
  ASSERT_TRUE(put(poured).ok());
  for (int k = 0; k < 300 && into.welcome().state().scene() != "pool"; ++k) {
    into.next_frame(milliseconds(100));
  }
  EXPECT_EQ(into.welcome().state().scene(), "pool") << "the session's viewer was not told";
  v1::SessionState state = joined();
  EXPECT_EQ(state.scene(), "pool");
  EXPECT_EQ(state.particles(), 800u);
  EXPECT_FLOAT_EQ(state.particle_spacing(), pool_spacing);
  EXPECT_EQ(into.snapshot().scene(), "pool");

  // Half the pool: half the water, each particle as large as a pool of 400 has them.
  v1::Snapshot half = poured;
  half.mutable_positions()->Truncate(3 * 400);
  half.mutable_velocities()->Truncate(3 * 400);
  ASSERT_TRUE(put(half).ok());
  state = joined();
  EXPECT_EQ(state.particles(), 400u);
  EXPECT_NEAR(state.particle_spacing(), pool_spacing * std::cbrt(2.0f), 1e-5f);

  // Refused before any solver is built for it: particles clumped at a point, of another count.
  v1::Snapshot clumped = own;
  for (int k = 0; k < clumped.positions_size(); ++k) clumped.set_positions(k, 0.3f);
  EXPECT_EQ(put(clumped).error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_EQ(joined().particles(), 400u);

  v1::Snapshot unknown = own;
  unknown.set_scene("lava_lamp");
  const grpc::Status refused = put(unknown);
  EXPECT_EQ(refused.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_NE(refused.error_message().find("Snapshot.scene"), std::string::npos)
      << refused.error_message();
  EXPECT_EQ(joined().particles(), 400u);

  ASSERT_TRUE(put(own).ok());
  state = joined();
  EXPECT_EQ(state.scene(), "dam_break");
  EXPECT_EQ(state.particles(), 1000u);
  EXPECT_FLOAT_EQ(state.particle_spacing(), dam_break_spacing);
  frame_from(into);
}

// Reads `viewer`'s stream until its state holds `done` (at most 30 s); whether it came to.
template <typename Done>
bool told(StreamClient& viewer, Done done) {
  for (int k = 0; k < 300 && !done(viewer.welcome().state()) && !viewer.ended(); ++k) {
    viewer.next_frame(milliseconds(100));
  }
  return done(viewer.welcome().state());
}

// A change of the session by one viewer (a scene, a count, a pause) is told to every viewer: each
// stream's Welcome.state follows it.
TEST(ServerTest, EveryViewerIsToldOfAChangeOfTheSession) {
  testing::ServerProcess server;
  const std::string& address = server.grpc_address();
  StreamClient creator(client::connect(address), small_hello(800));
  v1::Hello join = small_hello();
  join.set_join(creator.welcome().access().control_key());
  StreamClient friend_(client::connect(address), join);
  frame_from(creator);

  v1::Command command;
  command.set_scene("pool");
  friend_.command(command);
  command.set_particles(600);
  friend_.command(command);
  EXPECT_TRUE(told(creator, [](const v1::SessionState& state) {
    return state.scene() == "pool" && state.particles() == 600;
  })) << creator.welcome().state().ShortDebugString();
  EXPECT_TRUE(told(friend_, [](const v1::SessionState& state) {
    return state.scene() == "pool" && state.particles() == 600;
  })) << friend_.welcome().state().ShortDebugString();
  EXPECT_GT(creator.welcome().state().particle_spacing(), 0.0f);

  command.set_pause(true);
  creator.command(command);
  EXPECT_TRUE(told(friend_, [](const v1::SessionState& state) { return state.paused(); }));
  command.set_pause(false);
  friend_.command(command);
  EXPECT_TRUE(told(creator, [](const v1::SessionState& state) { return !state.paused(); }));
}

// A state is carried only for sessions of at most InputRules.max_state_particles; a larger one's
// request has no answer, and the stream goes on (another viewer may have made it larger while the
// request was on its way).
TEST(ServerTest, AStateRequestOfASessionTooLargeForAStreamIsNotAnsweredAndTheStreamGoesOn) {
  testing::ServerProcess server;
  StreamClient viewer(client::connect(server.grpc_address()), small_hello(16385));
  ASSERT_EQ(viewer.welcome().rules().max_state_particles(), 16384u);
  frame_from(viewer);
  v1::ClientMessage request;
  request.mutable_state_request();
  ASSERT_TRUE(viewer.send_raw(request));
  EXPECT_FALSE(viewer.take_state(seconds(2)));
  frame_from(viewer);
  EXPECT_FALSE(viewer.ended()) << viewer.status().error_message();
}

// Two viewers' wishes met in one rebuild, and one of them does not fit the GPU (a count past its
// memory): that viewer's stream ends, not the other's, whose wish stands.
TEST(ServerTest, AWishThatDoesNotFitTheGpuEndsItsAskersStreamAndTheOthersStand) {
  testing::ServerProcess server({"--backend", "gpu", "--gpu-memory", "64"});
  const std::string& address = server.grpc_address();
  StreamClient greedy(client::connect(address), small_hello(1000));
  v1::Hello join = small_hello();
  join.set_join(greedy.welcome().access().control_key());
  StreamClient other(client::connect(address), join);
  frame_from(greedy);
  frame_from(other);
  v1::Command command;
  command.set_scene("double_dam_break");  // rebuilt now: the next rebuild waits half a second
  other.command(command);
  ASSERT_TRUE(told(other, [](const v1::SessionState& state) {
    return state.scene() == "double_dam_break";
  })) << other.status().error_message();
  command.set_particles(1000000);
  greedy.command(command);
  command.set_scene("pool");
  other.command(command);
  EXPECT_TRUE(told(other, [](const v1::SessionState& state) {
    return state.scene() == "pool" && state.particles() == 1000u;
  })) << other.welcome().state().ShortDebugString() << " " << other.status().error_message();
  for (int k = 0; k < 300 && !greedy.ended(); ++k) greedy.next_frame(milliseconds(100));
  EXPECT_EQ(greedy.status().error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED)
      << greedy.status().error_message();
  EXPECT_FALSE(other.ended()) << other.status().error_message();
}

// The viewer given `access` comes back after its network dropped.
std::unique_ptr<StreamClient> resume(const std::string& address, const v1::Access& access) {
  v1::Hello hello = small_hello();
  hello.mutable_resume()->set_key(access.resume_key());
  return std::make_unique<StreamClient>(client::connect(address), hello);
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

  const auto back = resume(address, access);
  EXPECT_EQ(back->welcome().session_id(), session);
  EXPECT_TRUE(back->welcome().access().control()) << "the creator came back as a viewer";
  EXPECT_NE(back->welcome().access().resume_key(), access.resume_key());
  // Not a new fluid: time went on from where it was.
  EXPECT_GE(frame_from(*back).sim_time(), time_before);
}

// A viewer that resumes with its screen turned (portrait after landscape: a phone turned while
// its network was gone) sees the whole tank again, as a new viewer of that shape does; the fluid
// is paused, so the two frames differ only by their cameras.
TEST(ServerTest, AViewerResumedTurnedSeesTheTankFittedToItsNewShape) {
  testing::ServerProcess server;
  const std::string& address = server.grpc_address();
  auto first = std::make_unique<StreamClient>(client::connect(address), small_hello());
  v1::Command pause;
  pause.set_pause(true);
  first->command(pause);
  ASSERT_TRUE(told(*first, [](const v1::SessionState& state) { return state.paused(); }));
  const v1::Access access = first->welcome().access();
  first->drop();
  first.reset();

  v1::Hello turned = small_hello();
  turned.mutable_viewport()->set_width(120);
  turned.mutable_viewport()->set_height(160);
  v1::Hello fresh = turned;
  turned.mutable_resume()->set_key(access.resume_key());
  fresh.set_join(access.view_key());
  StreamClient back(client::connect(address), turned);
  StreamClient other(client::connect(address), fresh);
  const auto picture = [](StreamClient& stream) {
    v1::Frame frame;
    for (int k = 0; k < 3; ++k) frame = frame_from(stream);  // the pause's last step shown
    EXPECT_EQ(frame.width(), 120u);
    EXPECT_EQ(frame.height(), 160u);
    return codec::decode_jpeg(
        {reinterpret_cast<const std::uint8_t*>(frame.jpeg().data()), frame.jpeg().size()});
  };
  const codec::ImageRgba resumed = picture(back), joined = picture(other);
  ASSERT_EQ(resumed.pixels.size(), joined.pixels.size());
  double difference = 0.0;
  for (std::size_t k = 0; k < resumed.pixels.size(); ++k) {
    difference += std::abs(int(resumed.pixels[k]) - int(joined.pixels[k]));
  }
  difference /= double(resumed.pixels.size());
  std::printf("resumed turned vs a new viewer of that shape: %.2f levels apart on average\n",
              difference);
  EXPECT_LT(difference, 1.0) << "the resumed camera was not fitted to the turned frames";
}

// A viewport beyond the server's largest frame is not refused: its frames come scaled down to the
// limits with its shape kept (a phone's portrait screen on a server limited to landscape's).
TEST(ServerTest, AViewportBeyondTheServersLimitsGetsFramesScaledDownWithItsShape) {
  testing::ServerProcess server({"--max-width", "160", "--max-height", "120"});
  v1::Hello portrait = small_hello();
  portrait.mutable_viewport()->set_width(240);
  portrait.mutable_viewport()->set_height(320);
  StreamClient stream(client::connect(server.grpc_address()), portrait);
  v1::Frame frame = frame_from(stream);
  EXPECT_EQ(frame.width(), 90u);
  EXPECT_EQ(frame.height(), 120u);
  v1::Command wide;
  wide.mutable_viewport()->set_width(480);
  wide.mutable_viewport()->set_height(240);
  stream.command(wide);
  for (int k = 0; k < 90 && frame.width() != 160u; ++k) frame = frame_from(stream);
  EXPECT_EQ(frame.width(), 160u);
  EXPECT_EQ(frame.height(), 80u);
  EXPECT_FALSE(stream.ended()) << stream.status().error_message();
}

// The session forgets departed viewers by when they left, not when they joined: the creator,
// connected while many others came and went, still resumes after its own network drops.
TEST(ServerTest, TheFirstViewerResumesAfterMoreThanTheKeptOthersDropped) {
  testing::ServerProcess server;
  const std::string& address = server.grpc_address();
  auto first = std::make_unique<StreamClient>(client::connect(address), small_hello());
  const std::string session = first->welcome().session_id();
  v1::Hello join = small_hello();
  join.set_join(first->welcome().access().view_key());
  const auto join_session = [&] {
    for (int attempt = 0;; ++attempt) {
      try {
        return std::make_unique<StreamClient>(client::connect(address), join);
      } catch (const StreamError& refused) {
        // The seats of those who just dropped are free from the server's next tick.
        if (refused.code() != grpc::StatusCode::RESOURCE_EXHAUSTED || attempt == 50) throw;
        std::this_thread::sleep_for(milliseconds(100));
      }
    }
  };
  for (std::size_t k = 0; k < server::kMaxDepartedViewers; ++k) {
    const auto passing = join_session();
    ASSERT_EQ(passing->welcome().session_id(), session);
    frame_from(*passing);
    passing->drop();
  }
  frame_from(*first);
  const v1::Access access = first->welcome().access();
  first->drop();
  first.reset();

  const auto back = resume(address, access);
  EXPECT_EQ(back->welcome().session_id(), session);
  EXPECT_TRUE(back->welcome().access().control());
}

// A session whose creator drops while a second viewer, with the view key, watches it; the state
// the creator carried on by itself meanwhile (as if for 100 s).
struct WatchedDrop {
  std::string session;
  v1::Access creator_access;
  std::unique_ptr<StreamClient> watcher;
  v1::Snapshot carried_on;
};
WatchedDrop creator_drops_while_watched(const std::string& address) {
  auto creator = std::make_unique<StreamClient>(client::connect(address), small_hello(800));
  v1::Hello join = small_hello();
  join.set_join(creator->welcome().access().view_key());
  WatchedDrop dropped{creator->welcome().session_id(), creator->welcome().access(),
                      std::make_unique<StreamClient>(client::connect(address), join), {}};
  frame_from(*creator);
  frame_from(*dropped.watcher);
  dropped.carried_on = creator->snapshot();
  dropped.carried_on.set_time(dropped.carried_on.time() + 100.0);
  creator->drop();
  return dropped;
}

// Whether `viewer` shows a frame of simulated time `time` or later within 100 frames.
bool shows_time(StreamClient& viewer, double time) {
  for (int k = 0; k < 100; ++k) {
    if (frame_from(viewer).sim_time() >= time) return true;
  }
  return false;
}

// How a stream opened with `hello` ends at once: its status and sentence (OK when it opens).
std::pair<grpc::StatusCode, std::string> refusal_of(const std::string& address,
                                                    const v1::Hello& hello) {
  try {
    const StreamClient opened(client::connect(address), hello);
  } catch (const StreamError& e) {
    return {e.code(), e.what()};
  }
  return {grpc::StatusCode::OK, {}};
}

// A viewer that carried the fluid on by itself while its network was down hands it back as it
// resumes (Hello.resume.state), into the session another device watched throughout. A state the
// session does not take, or one from a viewer with the view key, is refused and leaves the viewer
// as it was: free to resume, or still connected.
TEST(ServerTest, AResumeHandsBackTheFluidCarriedOnIntoTheSessionLeft) {
  testing::ServerProcess server;
  const std::string& address = server.grpc_address();
  auto [session, creator_access, watcher, carried_on] = creator_drops_while_watched(address);
  const v1::Access watcher_access = watcher->welcome().access();

  const auto resume_with = [&](const v1::Access& access, const v1::Snapshot& state) {
    v1::Hello hello = small_hello();
    hello.mutable_resume()->set_key(access.resume_key());
    *hello.mutable_resume()->mutable_state() = state;
    return hello;
  };
  const auto refusal = [&](const v1::Access& access, const v1::Snapshot& state) {
    return refusal_of(address, resume_with(access, state));
  };
  v1::Snapshot outside = carried_on;
  outside.set_positions(4, 50.0f);
  auto [code, why] = refusal(creator_access, outside);
  EXPECT_EQ(code, grpc::StatusCode::INVALID_ARGUMENT) << why;
  EXPECT_NE(why.find("Snapshot"), std::string::npos) << why;
  v1::Snapshot uneven = carried_on;
  uneven.add_positions(0.5f);
  std::tie(code, why) = refusal(creator_access, uneven);
  EXPECT_EQ(code, grpc::StatusCode::INVALID_ARGUMENT) << why;
  EXPECT_NE(why.find("Hello.resume.state"), std::string::npos) << why;

  const auto back =
      std::make_unique<StreamClient>(client::connect(address), resume_with(creator_access, carried_on));
  EXPECT_EQ(back->welcome().session_id(), session);
  EXPECT_TRUE(back->welcome().access().control());
  EXPECT_TRUE(shows_time(*watcher, carried_on.time()))
      << "the watcher's session did not go on from the fluid handed back";

  // Refused while its old connection is still up (not known dead yet), it keeps that connection.
  std::tie(code, why) = refusal(watcher_access, carried_on);
  EXPECT_EQ(code, grpc::StatusCode::PERMISSION_DENIED) << why;
  EXPECT_NE(why.find("control key"), std::string::npos) << why;
  frame_from(*watcher);
  EXPECT_FALSE(watcher->ended()) << watcher->status().error_message();
  watcher->drop();
  watcher.reset();
  const auto watcher_back = resume(address, watcher_access);
  EXPECT_EQ(watcher_back->welcome().session_id(), session);
  EXPECT_FALSE(watcher_back->welcome().access().control());
}

// A viewer away past the grace (0 s here) has lost its seat, but the session lives on while
// another device watches: a resume that also gives the session's key joins it again, with that
// key's access and the fluid it carried on; without the key it finds nothing, and a key of a
// session that ended or a state from the view key's seat is refused, naming the field.
TEST(ServerTest, AViewerWhoseSeatWasForgottenRejoinsTheSessionByItsKey) {
  testing::ServerProcess server({"--resume-grace", "0"});
  const std::string& address = server.grpc_address();
  auto [session, creator_access, watcher, carried_on] = creator_drops_while_watched(address);
  // Once the server has seen the drop, the seat is forgotten at once.
  for (int k = 0; k < 100 && server.metric("fluidcast_viewers") != 1; ++k) {
    std::this_thread::sleep_for(milliseconds(50));
  }
  ASSERT_EQ(server.metric("fluidcast_viewers"), 1);

  const auto resume_with = [&](const std::string& session_key, const v1::Snapshot* state) {
    v1::Hello hello = small_hello();
    hello.mutable_resume()->set_key(creator_access.resume_key());
    hello.mutable_resume()->set_session_key(session_key);
    if (state) *hello.mutable_resume()->mutable_state() = *state;
    return hello;
  };
  const auto opens = [&](const std::string& session_key, const v1::Snapshot* state) {
    return std::make_unique<StreamClient>(client::connect(address), resume_with(session_key, state));
  };
  const auto refusal = [&](const std::string& session_key, const v1::Snapshot* state) {
    return refusal_of(address, resume_with(session_key, state));
  };
  auto [code, why] = refusal("", &carried_on);
  EXPECT_EQ(code, grpc::StatusCode::NOT_FOUND) << why;
  EXPECT_NE(why.find("Hello.resume.key"), std::string::npos) << why;
  std::tie(code, why) = refusal(std::string(32, 'x'), &carried_on);
  EXPECT_EQ(code, grpc::StatusCode::NOT_FOUND) << why;
  EXPECT_NE(why.find("Hello.resume.session_key"), std::string::npos) << why;
  std::tie(code, why) = refusal(creator_access.view_key(), &carried_on);
  EXPECT_EQ(code, grpc::StatusCode::PERMISSION_DENIED) << why;
  EXPECT_NE(why.find("Hello.resume.state"), std::string::npos) << why;

  const auto back = opens(creator_access.control_key(), &carried_on);
  EXPECT_EQ(back->welcome().session_id(), session);
  EXPECT_TRUE(back->welcome().access().control());
  EXPECT_NE(back->welcome().access().resume_key(), creator_access.resume_key());
  EXPECT_TRUE(shows_time(*watcher, carried_on.time()))
      << "the watcher's session did not go on from the fluid handed back";
  const auto onlooker = opens(creator_access.view_key(), nullptr);  // as the view key allows
  EXPECT_EQ(onlooker->welcome().session_id(), session);
  EXPECT_FALSE(onlooker->welcome().access().control());
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

  // A new count rebuilds the fluid, which falls as the old one did: the device is still tilted.
  v1::ClientMessage recount;
  recount.mutable_command()->set_particles(800);
  stream.send(recount);
  v1::Snapshot rebuilt;
  for (int k = 0; k < 100 && rebuilt.positions_size() != 3 * 800; ++k) {
    frame_from(stream);
    rebuilt = stream.snapshot();
  }
  ASSERT_EQ(rebuilt.positions_size(), 3 * 800);
  EXPECT_NEAR(rebuilt.gravity().x(), g.x(), 1e-4f);
  EXPECT_NEAR(rebuilt.gravity().y(), g.y(), 1e-4f);
  EXPECT_NEAR(rebuilt.gravity().z(), g.z(), 1e-4f);
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
  // Swept back and forth, 20 frames a round, until the water near it moves (one round, here; a
  // loaded machine once showed none after the first); ten rounds without is a finger that stirs
  // nothing.
  const float centre_x = 0.5f * (touched.welcome().state().tank().min().x() +
                                 touched.welcome().state().tank().max().x());
  double stirred_speed = 0.0;
  double still_speed = 0.0;
  touched.pointer(0, v1::PointerEvent::DOWN, 0.45f, 0.7f);
  for (int round = 0; round < 10 && !(stirred_speed > 3.0 * still_speed + 0.02); ++round) {
    for (int k = 0; k < 20; ++k) {
      frame_from(touched);
      frame_from(calm);
      touched.pointer(0, v1::PointerEvent::MOVE, 0.45f + 0.01f * float(k % 10), 0.7f);
    }
    stirred_speed = mean_speed_near(touched.snapshot(), centre_x, 0.3f);
    still_speed = mean_speed_near(calm.snapshot(), centre_x, 0.3f);
    std::printf("round %d: mean speed near the finger %.3f m/s stirred, %.3f m/s left alone\n",
                round, stirred_speed, still_speed);
  }
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
  const v1::Snapshot moved = from.snapshot();
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
  const v1::Snapshot landed = into.snapshot();
  EXPECT_EQ(landed.positions_size(), 3 * 800);
  EXPECT_GE(landed.time(), moved.time());
  EXPECT_NEAR(landed.gravity().x(), moved.gravity().x(), 1e-4f);
  // A client that reads each answer and calls again at once is never refused, though the server
  // may not yet have been told that the answer before went out.
  for (int call = 0; call < 20; ++call) {
    EXPECT_EQ(into.snapshot().positions_size(), 3 * 800) << "call " << call;
  }

  // A fluid put back far ahead of the session's clock (a client ran it locally for a while): the
  // simulation speed its viewers see is measured from there on, not across the jump.
  const double ahead = moved.time() + 1000.0;
  put.mutable_snapshot()->set_time(ahead);
  {
    grpc::ClientContext context;
    ASSERT_TRUE(stub->PutSnapshot(&context, put, &reply).ok());
  }
  for (int shown = 0; shown < 10;) {
    const v1::Frame frame = frame_from(into);
    if (frame.sim_time() < ahead) continue;  // drawn before the snapshot landed
    EXPECT_LT(frame.sim_speed(), 10.0f) << "at " << frame.sim_time() << " s";
    ++shown;
  }

  // A particle out of place or too fast, or a gravity no Tilt could set: refused, naming which
  // and what it may be, and the fluid stays.
  const auto refused_saying = [&](const v1::PutSnapshotRequest& request) {
    grpc::ClientContext context;
    const grpc::Status status = stub->PutSnapshot(&context, request, &reply);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
    return status.error_message();
  };
  v1::PutSnapshotRequest bad = put;
  bad.mutable_snapshot()->set_positions(7, std::numeric_limits<float>::quiet_NaN());
  std::string said = refused_saying(bad);
  EXPECT_NE(said.find("particle 2's position ("), std::string::npos) << said;
  EXPECT_NE(said.find(", nan, "), std::string::npos) << said;
  EXPECT_NE(said.find("SessionState.tank"), std::string::npos) << said;
  bad = put;
  bad.mutable_snapshot()->set_velocities(4, -2000.0f);
  said = refused_saying(bad);
  EXPECT_NE(said.find("particle 1's velocity"), std::string::npos) << said;
  EXPECT_NE(said.find("faster than 1000 m/s"), std::string::npos) << said;
  bad = put;
  bad.mutable_snapshot()->mutable_gravity()->set_y(-300.0f);
  said = refused_saying(bad);
  EXPECT_NE(said.find("Snapshot.gravity"), std::string::npos) << said;
  EXPECT_NE(said.find("0.1 to 200 m/s² (InputRules.tilt_gravity)"), std::string::npos) << said;
  EXPECT_EQ(into.snapshot().positions_size(), 3 * 800);

  // No snapshot, no particles, or a clock that cannot be a session's: refused, naming the field,
  // and the fluid stays.
  const auto put_status = [&](const v1::PutSnapshotRequest& request) {
    grpc::ClientContext context;
    return stub->PutSnapshot(&context, request, &reply);
  };
  v1::PutSnapshotRequest without = put;
  without.clear_snapshot();
  grpc::Status answer = put_status(without);
  EXPECT_EQ(answer.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_NE(answer.error_message().find("PutSnapshotRequest.snapshot"), std::string::npos)
      << answer.error_message();
  without.mutable_snapshot()->set_time(1.0);
  answer = put_status(without);
  EXPECT_EQ(answer.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_NE(answer.error_message().find("no particles"), std::string::npos)
      << answer.error_message();
  v1::PutSnapshotRequest far_ahead = put;
  *far_ahead.mutable_snapshot() = moved;
  far_ahead.mutable_snapshot()->set_time(1e300);
  answer = put_status(far_ahead);
  EXPECT_EQ(answer.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_NE(answer.error_message().find("Snapshot.time"), std::string::npos)
      << answer.error_message();
  EXPECT_EQ(into.snapshot().positions_size(), 3 * 800);

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
  EXPECT_EQ(into.snapshot().positions_size(), 3 * 800);
}

// Snapshot calls on one connection whose windows stay at gRPC's initial 64 kB, so that an answer
// larger than that waits in the server until the test reads it (finish). The test numbers the
// calls; on the way out, passed or not, every call is cancelled and the queue drained.
class UnreadSnapshotCalls {
 public:
  static constexpr int kStarted = 0;  // the server's answer began: its initial metadata came
  static constexpr int kFinished = 1;
  static void* tag(int call, int event) {
    return reinterpret_cast<void*>(static_cast<std::intptr_t>(2 * call + event + 1));
  }

  explicit UnreadSnapshotCalls(const std::string& address) {
    grpc::ChannelArguments arguments;
    arguments.SetInt(GRPC_ARG_HTTP2_BDP_PROBE, 0);  // the windows stay at their initial 64 kB
    arguments.SetMaxReceiveMessageSize(64 << 20);
    stub_ = v1::Fluidcast::NewStub(
        grpc::CreateCustomChannel(address, grpc::InsecureChannelCredentials(), arguments));
  }
  ~UnreadSnapshotCalls() {
    for (Call& call : calls_) call.context.TryCancel();
    queue_.Shutdown();
    void* event = nullptr;
    bool ok = false;
    while (queue_.Next(&event, &ok)) {
    }
  }

  // Starts a call; its kStarted event comes when the server begins to answer. `watch`: no event
  // until finish() (a call answered at once with an error).
  void get(int call, const v1::SnapshotRequest& request, bool watch = true) {
    calls_[call].get = stub_->AsyncGetSnapshot(&calls_[call].context, request, &queue_);
    if (watch) calls_[call].get->ReadInitialMetadata(tag(call, kStarted));
  }
  void put(int call, const v1::PutSnapshotRequest& request) {
    calls_[call].put = stub_->AsyncPutSnapshot(&calls_[call].context, request, &queue_);
    calls_[call].put->ReadInitialMetadata(tag(call, kStarted));
  }
  void cancel(int call) { calls_[call].context.TryCancel(); }
  // Reads the call's answer; its kFinished event comes once it is in.
  void finish(int call) {
    Call& c = calls_[call];
    if (c.get) c.get->Finish(&c.snapshot, &c.status, tag(call, kFinished));
    if (c.put) c.put->Finish(&c.put_reply, &c.status, tag(call, kFinished));
  }
  // The next event within `within`, or nullptr.
  void* next_event(std::chrono::milliseconds within) {
    void* got = nullptr;
    bool ok = false;
    const auto status = queue_.AsyncNext(&got, &ok, std::chrono::system_clock::now() + within);
    return status == grpc::CompletionQueue::GOT_EVENT ? got : nullptr;
  }
  const grpc::Status& status(int call) const { return calls_[call].status; }
  const v1::Snapshot& snapshot(int call) const { return calls_[call].snapshot; }

 private:
  struct Call {
    grpc::ClientContext context;
    std::unique_ptr<grpc::ClientAsyncResponseReader<v1::Snapshot>> get;
    std::unique_ptr<grpc::ClientAsyncResponseReader<v1::PutSnapshotReply>> put;
    v1::Snapshot snapshot;
    v1::PutSnapshotReply put_reply;
    grpc::Status status;
  };
  std::unique_ptr<v1::Fluidcast::Stub> stub_;
  grpc::CompletionQueue queue_;
  std::array<Call, 8> calls_;
};

// A client that reads none of its snapshot answers: its connection's windows are too small for
// one, so the server holds each answered call until the client reads it. Two such answers, then a
// third call with the key waits (a fourth on that connection is refused), and so does a call with
// the key from another of the address's connections (the address's answers are shared: a client's
// many connections hold no more); another key is served. Each waiting call is carried out once the
// client reads an answer, in the order they came.
TEST(ServerTest, ASnapshotCallWaitsWhileTwoAnswersToItsAddressAreUnread) {
  testing::ServerProcess server;
  constexpr std::uint32_t kParticles = 8000;  // 192 kB a snapshot: three windows of 64 kB
  StreamClient owner(client::connect(server.grpc_address()), small_hello(kParticles));
  frame_from(owner);
  UnreadSnapshotCalls calls(server.grpc_address());
  using Calls = UnreadSnapshotCalls;
  v1::SnapshotRequest request;
  request.set_key(owner.welcome().access().view_key());

  for (int call = 0; call < 2; ++call) {  // the answers an address may leave unread
    calls.get(call, request);
    ASSERT_EQ(calls.next_event(seconds(30)), Calls::tag(call, Calls::kStarted)) << "call " << call;
  }
  calls.get(2, request);
  EXPECT_EQ(calls.next_event(milliseconds(1500)), nullptr) << "the third call was answered at once";
  calls.get(3, request, false);
  calls.finish(3);
  ASSERT_EQ(calls.next_event(seconds(30)), Calls::tag(3, Calls::kFinished));
  EXPECT_EQ(calls.status(3).error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_NE(calls.status(3).error_message().find("under way"), std::string::npos)
      << calls.status(3).error_message();

  // The owner's connection: another key is served at once, the same key waits its turn.
  auto stub = v1::Fluidcast::NewStub(client::connect(server.grpc_address()));
  const auto get_on_owners_connection = [&stub](const std::string& key) {
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() + seconds(30));
    v1::SnapshotRequest other;
    other.set_key(key);
    v1::Snapshot snapshot;
    const grpc::Status status = stub->GetSnapshot(&context, other, &snapshot);
    return status.ok() ? snapshot.positions_size() : -int(status.error_code());
  };
  EXPECT_EQ(get_on_owners_connection(owner.welcome().access().control_key()), 3 * int(kParticles));
  auto same_key = std::async(std::launch::async, get_on_owners_connection, request.key());
  EXPECT_EQ(same_key.wait_for(milliseconds(1500)), std::future_status::timeout)
      << "the address's two answers are unread";

  calls.finish(0);
  std::set<void*> events;
  for (void* event; events.size() < 2 && (event = calls.next_event(seconds(30)));) {
    events.insert(event);
  }
  EXPECT_EQ(events,
            (std::set<void*>{Calls::tag(0, Calls::kFinished), Calls::tag(2, Calls::kStarted)}))
      << "the call that waited longest goes first";
  calls.finish(1);
  EXPECT_EQ(same_key.get(), 3 * int(kParticles)) << "once the client read another answer";
  calls.finish(2);
  for (int left = 2; left > 0 && calls.next_event(seconds(30)); --left) {
  }
  for (int call : {0, 1, 2}) {
    EXPECT_TRUE(calls.status(call).ok())
        << "call " << call << ": " << calls.status(call).error_message();
    EXPECT_EQ(calls.snapshot(call).positions_size(), 3 * int(kParticles)) << "call " << call;
  }
}

// A PutSnapshot that waited behind two unread answers and that its client gave up on is not
// carried out when its turn comes: the fluid stays as it was, and the connection's next call with
// the key is served once the server has ended the cancelled one.
TEST(ServerTest, ASnapshotCallCancelledWhileItWaitsIsNotCarriedOut) {
  testing::ServerProcess server;
  constexpr std::uint32_t kParticles = 8000;
  StreamClient owner(client::connect(server.grpc_address()), small_hello(kParticles));
  StreamClient other(client::connect(server.grpc_address()), small_hello(800));
  frame_from(owner);
  frame_from(other);
  UnreadSnapshotCalls calls(server.grpc_address());
  using Calls = UnreadSnapshotCalls;
  const std::string& key = owner.welcome().access().control_key();
  v1::SnapshotRequest get;
  get.set_key(key);
  for (int call = 0; call < 2; ++call) {
    calls.get(call, get);
    ASSERT_EQ(calls.next_event(seconds(30)), Calls::tag(call, Calls::kStarted)) << "call " << call;
  }
  v1::PutSnapshotRequest put;
  put.set_key(key);
  *put.mutable_snapshot() = other.snapshot();
  calls.put(2, put);
  EXPECT_EQ(calls.next_event(milliseconds(1500)), nullptr) << "the put was carried out at once";
  calls.cancel(2);
  // The server hears of a cancel on threads of its own: a put whose turn came first would land
  // (seen once in a few dozen runs without this wait).
  std::this_thread::sleep_for(seconds(1));

  calls.finish(0);
  calls.finish(1);
  calls.finish(2);
  std::set<void*> events;  // the put's start comes too, as cancelled
  for (int call = 0; call < 3; ++call) {
    while (!events.contains(Calls::tag(call, Calls::kFinished))) {
      void* event = calls.next_event(seconds(30));
      ASSERT_TRUE(event) << "call " << call << " did not finish";
      events.insert(event);
    }
  }
  while (!events.contains(Calls::tag(2, Calls::kStarted))) {
    void* event = calls.next_event(seconds(30));
    ASSERT_TRUE(event) << "the put's start did not come back";
    events.insert(event);
  }
  for (int call : {0, 1}) EXPECT_TRUE(calls.status(call).ok()) << "call " << call;
  for (int k = 0; k < 5; ++k) frame_from(owner);
  EXPECT_EQ(owner.snapshot().positions_size(), 3 * int(kParticles));

  // The client's cancel ends its call at once; the server ends it when its turn comes, after the
  // answers before it went out, and until then the key is still under way on this connection.
  grpc::StatusCode answer = grpc::StatusCode::UNKNOWN;
  for (int call = 3; call < 8 && answer != grpc::StatusCode::OK; ++call) {
    calls.get(call, get, false);
    calls.finish(call);
    ASSERT_EQ(calls.next_event(seconds(30)), Calls::tag(call, Calls::kFinished));
    answer = calls.status(call).error_code();
    if (answer == grpc::StatusCode::OK) {
      EXPECT_EQ(calls.snapshot(call).positions_size(), 3 * int(kParticles));
    } else {
      EXPECT_EQ(answer, grpc::StatusCode::RESOURCE_EXHAUSTED) << calls.status(call).error_message();
      std::this_thread::sleep_for(milliseconds(200));
    }
  }
  EXPECT_EQ(answer, grpc::StatusCode::OK) << "the cancelled call still holds its key";
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
  // The transport's windows fill: from the first frame dropped unread on, memory is at its
  // steady state (on a busy machine that takes longer than on an idle one).
  const auto filling = std::chrono::steady_clock::now();
  while (server.metric("fluidcast_frames_dropped_total") <= 0 &&
         std::chrono::steady_clock::now() - filling < seconds(20)) {
    acknowledge_for(milliseconds(500));
  }
  acknowledge_for(seconds(1));
  const long before = server.resident_kb();
  const double dropped_before = server.metric("fluidcast_frames_dropped_total");
  acknowledge_for(seconds(6));
  const long after = server.resident_kb();
  const double dropped = server.metric("fluidcast_frames_dropped_total") - dropped_before;
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
  context.set_deadline(std::chrono::system_clock::now() + seconds(60));
  auto stream = stub->Stream(&context);
  v1::ClientMessage message;
  *message.mutable_hello() = small_hello();
  message.mutable_hello()->mutable_quality()->set_max_fps(60);
  ASSERT_TRUE(stream->Write(message));
  v1::ServerMessage received;
  ASSERT_TRUE(stream->Read(&received));
  ASSERT_TRUE(received.has_welcome());
  // The first frame waits for the renderer's first pipelines (seconds on a loaded machine): the
  // frames are counted from it on.
  do {
    ASSERT_TRUE(stream->Read(&received)) << "no first frame";
  } while (!received.has_frame());
  int frames = 0;
  std::thread stop([&] {
    std::this_thread::sleep_for(seconds(4));
    context.TryCancel();
  });
  while (stream->Read(&received)) frames += received.has_frame();
  stop.join();
  std::printf("frames in 4 s after the first, without acknowledgements: %d\n", frames);
  EXPECT_GE(frames, 3);  // two more, then one a second
  EXPECT_LE(frames, 9);  // not the 30 or 60 a second of a viewer that acknowledges
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

// A server held to 64 MiB of GPU memory (--gpu-memory): a viewer whose new frame size needs more
// keeps its frames at the size they have and goes on, as do its session and the other viewer; a
// size that fits is taken after it; a new viewer asking the size that does not fit is refused
// with RESOURCE_EXHAUSTED naming its viewport.
TEST(ServerTest, AFrameSizeWithoutGpuMemoryKeepsTheFramesAtTheirSizeAndIsRefusedAtTheStart) {
  testing::ServerProcess server({"--gpu-memory", "64"});
  const std::string& address = server.grpc_address();
  StreamClient first(client::connect(address), small_hello());
  v1::Hello join = small_hello();
  join.set_join(first.welcome().access().view_key());
  StreamClient second(client::connect(address), join);
  frame_from(first);
  frame_from(second);

  const auto resize = [&](std::uint32_t width, std::uint32_t height) {
    v1::Command command;
    command.mutable_viewport()->set_width(width);
    command.mutable_viewport()->set_height(height);
    first.command(command);
  };
  resize(3840, 2160);
  for (int k = 0; k < 30; ++k) {  // a second at 30 frames/s: the resize was tried
    const v1::Frame frame = frame_from(first);
    ASSERT_EQ(frame.width(), 160u);
    ASSERT_EQ(frame.height(), 120u);
  }
  const double before = frame_from(second).sim_time();
  double after = before;  // a slow machine's ticks may show a step's time twice
  for (int k = 0; k < 60 && after <= before; ++k) after = frame_from(second).sim_time();
  EXPECT_GT(after, before) << "the session's fluid stopped";
  resize(320, 240);
  bool resized = false;
  for (int k = 0; k < 60 && !resized; ++k) resized = frame_from(first).width() == 320u;
  EXPECT_TRUE(resized) << "a size that fits was not taken after one that did not";
  EXPECT_FALSE(first.ended()) << first.status().error_message();

  v1::Hello large = small_hello();
  large.mutable_viewport()->set_width(3840);
  large.mutable_viewport()->set_height(2160);
  try {
    StreamClient refused(client::connect(address), large);
    ADD_FAILURE() << "a viewer whose frames find no GPU memory was admitted";
  } catch (const StreamError& e) {
    EXPECT_EQ(e.code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
    EXPECT_NE(std::string(e.what()).find("Viewport"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(first.finish().ok());
  EXPECT_TRUE(second.finish().ok());
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

}  // namespace
}  // namespace fluidcast

// The native client's handoff against the real server when only the connection drops (a phone's
// network; the server stays up): the client carries the fluid on here and, once it reconnects,
// puts it back into the session it left, where another device watched throughout.
#include <gtest/gtest.h>

#include <chrono>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "handoff_sides.h"
#include "handoff_stream.h"
#include "server_process.h"
#include "stream_client.h"

namespace fluidcast::client {
namespace {

using std::chrono::milliseconds;

// The handoff's two sides, the real ones, with the last server stream and the local fluid's
// start kept where the test can see them.
struct WatchedSides {
  std::mutex mutex;
  std::shared_ptr<StreamClient> last_stream;
  bool local_started = false;
  std::vector<std::string> said;
  std::function<void()> before_resume;  // runs before a Hello that resumes goes out

  HandoffSides around(HandoffSides sides) {
    sides.connect = [this, connect = sides.connect](const v1::Hello& hello,
                                                    std::stop_token closing) {
      if (hello.has_resume() && before_resume) before_resume();
      std::shared_ptr<FluidStream> stream = connect(hello, closing);
      const std::lock_guard lock(mutex);
      last_stream = std::dynamic_pointer_cast<StreamClient>(stream);
      return stream;
    };
    sides.start_local = [this, start = sides.start_local](const v1::Hello& hello) {
      std::shared_ptr<FluidStream> local = start(hello);
      const std::lock_guard lock(mutex);
      local_started = true;
      return local;
    };
    return sides;
  }
  bool heard(const std::string& part) {
    const std::lock_guard lock(mutex);
    for (const std::string& line : said) {
      if (line.find(part) != std::string::npos) return true;
    }
    return false;
  }
};

// Reads frames until `done` holds, at most `within`; whether it did.
template <typename Done>
bool read_until(FluidStream& stream, Done done, std::chrono::seconds within) {
  const auto end = std::chrono::steady_clock::now() + within;
  while (!done() && std::chrono::steady_clock::now() < end) stream.next_frame(milliseconds(20));
  return done();
}

// Whether a frame is shown within `within` (those from before a handback's state went in are
// not).
bool shows_a_frame(FluidStream& stream, std::chrono::seconds within) {
  const auto end = std::chrono::steady_clock::now() + within;
  while (std::chrono::steady_clock::now() < end) {
    if (stream.next_frame(milliseconds(20))) return true;
  }
  return false;
}

// `flags`: the server's.
void hand_back_after_a_drop(std::vector<std::string> flags) {
  testing::ServerProcess server(std::move(flags));
  WatchedSides watched;
  // The way back starts once the server has seen the drop (its seat kept, or forgotten at once).
  watched.before_resume = [&] {
    for (int k = 0; k < 100 && server.metric("fluidcast_viewers") != 1; ++k) {
      std::this_thread::sleep_for(milliseconds(50));
    }
  };
  HandoffOptions options;
  options.snapshot_every = milliseconds(100);
  options.retry_every = milliseconds(200);
  options.say = [&](const std::string& line) {
    const std::lock_guard lock(watched.mutex);
    watched.said.push_back(line);
  };
  v1::Hello hello;
  hello.mutable_viewport()->set_width(160);
  hello.mutable_viewport()->set_height(120);
  hello.mutable_create()->set_particles(1000);
  HandoffStream stream(hello, watched.around(handoff_sides(server.grpc_address(), 8000)), options);
  const std::string session = stream.welcome().session_id();
  ASSERT_FALSE(session.empty());

  v1::Hello join;  // a second device, watching with the view key
  *join.mutable_viewport() = hello.viewport();
  join.set_join(stream.welcome().access().view_key());
  StreamClient watcher(connect(server.grpc_address()), join);

  // The warm fluid here has started, and a few states went into it since.
  ASSERT_TRUE(read_until(
      stream,
      [&] {
        const std::lock_guard lock(watched.mutex);
        return watched.local_started;
      },
      std::chrono::seconds(60)));
  const auto warm = std::chrono::steady_clock::now();
  read_until(stream, [&] { return std::chrono::steady_clock::now() - warm > milliseconds(1000); },
             std::chrono::seconds(2));

  std::shared_ptr<StreamClient> first;
  {
    const std::lock_guard lock(watched.mutex);
    first = std::exchange(watched.last_stream, nullptr);
  }
  ASSERT_TRUE(first);
  first->drop();
  first.reset();
  ASSERT_TRUE(read_until(stream, [&] { return stream.simulating_here(); }, std::chrono::seconds(10)))
      << stream.status();
  ASSERT_TRUE(read_until(stream, [&] { return watched.heard("took the state"); },
                         std::chrono::seconds(30)))
      << stream.status();
  ASSERT_TRUE(read_until(stream, [&] { return !stream.simulating_here(); },
                         std::chrono::seconds(10)))
      << stream.status();

  EXPECT_TRUE(watched.heard("into the session it left")) << stream.status();
  EXPECT_EQ(stream.welcome().session_id(), session);
  EXPECT_EQ(server.metric("fluidcast_sessions"), 1) << "a second session was made";
  EXPECT_EQ(server.metric("fluidcast_viewers"), 2);
  EXPECT_FALSE(watcher.ended()) << watcher.end_reason();
  EXPECT_TRUE(watcher.next_frame(milliseconds(5000))) << "the watcher's stream stopped";
  EXPECT_TRUE(shows_a_frame(stream, std::chrono::seconds(10)))
      << "nothing streams after the handback";
  EXPECT_EQ(stream.close(), "");
  EXPECT_EQ(watcher.close(), "");
}

TEST(Handback, ADroppedConnectionHandsTheFluidBackIntoTheSessionItLeft) {
  hand_back_after_a_drop({});
}

// Away past the grace (0 s here), the client's seat is forgotten; the session lives on while the
// other device watches, and the client's way back takes a new seat in it with the session's key.
TEST(Handback, AClientWhoseSeatWasForgottenHandsTheFluidBackIntoTheSessionItLeft) {
  hand_back_after_a_drop({"--resume-grace", "0"});
}

}  // namespace
}  // namespace fluidcast::client

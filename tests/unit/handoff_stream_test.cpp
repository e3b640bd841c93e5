// The handoff without a server, a GPU or a window: fluids in memory stand in for a server's
// session and for one simulated here, and the test watches what HandoffStream shows and moves.
#include "handoff_stream.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <utility>
#include <vector>

namespace fluidcast::client {
namespace {

using std::chrono::milliseconds;

// What the in-memory server does; shared with the streams it opened.
struct FakeServer {
  std::mutex mutex;
  bool up = true;
  bool silent = false;             // its streams send nothing: a wedged server
  bool ends_streams = false;       // it ends every stream on purpose (an idle session, say)
  bool refuses_states = false;     // a state put into a session is refused
  bool viewers_control = true;     // false: every stream only watches
  bool forgets_sessions = false;    // a resume finds nothing (it restarted, the grace ran out)
  bool resumes_paused = false;      // a session resumed is paused (as someone left it)
  int full_for = 0;                 // resumes refused for now (the session's seats are taken)
  bool holds_loads = false;         // a state put in waits until this is false again...
  bool load_waiting = false;        // ...as one does now
  bool holds_goodbyes = false;      // a stream's goodbye waits until this is false again
  bool hangs = false;               // a connection is made only once its client closes (or 30 s)
  bool connecting = false;          // one is being made
  int goodbyes = 0;                 // streams closed in order
  std::condition_variable released;  // a load or goodbye held may go on
  std::uint32_t particles = 1000;  // of a session whose Hello names no count
  std::vector<v1::Snapshot> put;   // states put into its sessions
  std::vector<v1::Hello> hellos;   // of the streams it answered
  int streams = 0;
  int snapshots = 0;  // taken from its sessions
};

// A session whose clock advances 1 ms per frame read. Frames come one read late, as a real
// pipeline's do: the one returned was made at the previous read, from the state and the events
// seen then, so a state loaded in between shows only a read later.
class FakeFluid final : public FluidStream {
 public:
  FakeFluid(std::shared_ptr<FakeServer> server, const v1::Hello& hello) : server_(server) {
    const std::uint32_t asked = hello.create().particles();
    welcome_.mutable_state()->set_particles(asked ? asked : server ? server->particles : 1000);
    welcome_.mutable_state()->set_scene(hello.create().scene());
    welcome_.set_session_id(server ? "remote" : "local");
    welcome_.mutable_access()->set_control(!server || server->viewers_control);
    welcome_.mutable_access()->set_view_key("view-key");
    if (welcome_.access().control()) welcome_.mutable_access()->set_control_key("control-key");
    // A resume key of its own for each stream, as the server gives.
    static std::atomic<int> keys = 0;
    welcome_.mutable_access()->set_resume_key("resume-" + std::to_string(++keys));
    if (server && hello.has_resume() && server->resumes_paused) {
      paused_ = true;
      welcome_.mutable_state()->set_paused(true);
    }
    pending_ = make_frame();
  }

  const v1::Welcome& welcome() const override { return welcome_; }
  std::uint64_t send(v1::ClientMessage message) override {
    if (ended()) return 0;
    const std::lock_guard lock(mutex_);
    const std::uint64_t id = latency_.sent();
    if (message.has_command() && message.command().kind_case() == v1::Command::kPause) {
      paused_ = message.command().pause();
      // A session tells every viewer, the one that asked too, with the frame that shows it.
      told_paused_ = paused_;
      told_with_event_ = id;
    }
    if (message.has_command() && message.command().has_viewport()) {
      viewport_width_ = message.command().viewport().width();
    }
    if (message.has_pointer()) pointers_.push_back(message.pointer());
    last_event_ = id;
    return id;
  }
  std::optional<v1::Frame> next_frame(milliseconds timeout) override {
    if (ended() || (server_ && silent())) {
      std::this_thread::sleep_for(timeout);
      return std::nullopt;
    }
    std::this_thread::sleep_for(milliseconds(1));
    const std::lock_guard lock(mutex_);
    if (told_paused_ && pending_.input_event_id() >= told_with_event_) {
      welcome_.mutable_state()->set_paused(*std::exchange(told_paused_, {}));
    }
    if (!paused_) time_ += 0.001;
    return std::exchange(pending_, make_frame());
  }
  bool ended() const override {
    if (!server_) return false;
    const std::lock_guard lock(server_->mutex);
    return !server_->up || server_->ends_streams;
  }
  bool lost() const override {
    if (!server_) return false;
    const std::lock_guard lock(server_->mutex);
    return !server_->up;
  }
  std::string end_reason() const override {
    return !ended() ? "" : lost() ? "the server went away" : "nobody touched the fluid";
  }
  std::string close() override {
    if (server_) {
      std::unique_lock lock(server_->mutex);
      // Bounded: a goodbye said on the caller's thread fails the test rather than hangs it.
      server_->released.wait_for(lock, std::chrono::seconds(5),
                                       [this] { return !server_->holds_goodbyes; });
      ++server_->goodbyes;
    }
    return end_reason();
  }
  v1::Snapshot snapshot() override {
    if (ended()) throw std::runtime_error("no server");
    if (server_) {
      const std::lock_guard lock(server_->mutex);
      ++server_->snapshots;
    }
    const std::lock_guard lock(mutex_);
    v1::Snapshot snapshot;
    snapshot.set_time(time_);
    for (std::uint32_t k = 0; k < 3 * welcome_.state().particles(); ++k) snapshot.add_positions(0);
    return snapshot;
  }
  void load(const v1::Snapshot& snapshot) override {
    if (ended()) throw std::runtime_error("no server");
    if (server_) {
      std::unique_lock lock(server_->mutex);
      server_->load_waiting = server_->holds_loads;
      server_->released.wait(lock, [this] { return !server_->holds_loads; });
      server_->load_waiting = false;
      if (server_->refuses_states) throw std::invalid_argument("Snapshot: particle 7 is outside");
    }
    {
      const std::lock_guard lock(mutex_);
      time_ = snapshot.time();
      loaded_from_ = time_;
    }
    if (server_) {
      const std::lock_guard lock(server_->mutex);
      server_->put.push_back(snapshot);
    }
  }
  // The clock of the last state loaded (nothing loaded: negative).
  double loaded_from() const {
    const std::lock_guard lock(mutex_);
    return loaded_from_;
  }
  bool paused() const {
    const std::lock_guard lock(mutex_);
    return paused_;
  }
  // Another viewer paused the session, or set it going: the Welcome says so from the next frame
  // read, as a stream's does (ServerMessage.session).
  void paused_by_another(bool paused) {
    const std::lock_guard lock(mutex_);
    paused_ = paused;
    told_paused_ = paused;
    told_with_event_ = 0;
  }
  std::uint32_t viewport_width() const {
    const std::lock_guard lock(mutex_);
    return viewport_width_;
  }
  std::vector<v1::PointerEvent> pointers() const {
    const std::lock_guard lock(mutex_);
    return pointers_;
  }

 private:
  bool silent() const {
    const std::lock_guard lock(server_->mutex);
    return server_->silent;
  }
  v1::Frame make_frame() const {  // under mutex_
    v1::Frame frame;
    frame.set_sim_time(float(time_));
    frame.set_input_event_id(last_event_);
    return frame;
  }

  const std::shared_ptr<FakeServer> server_;  // null: a fluid simulated here
  v1::Welcome welcome_;
  mutable std::mutex mutex_;
  double time_ = 0.0;
  double loaded_from_ = -1.0;
  bool paused_ = false;
  std::optional<bool> told_paused_;  // for the Welcome, with the frame reflecting...
  std::uint64_t told_with_event_ = 0;  // ...this event
  std::uint32_t viewport_width_ = 0;  // the last a command asked for
  std::vector<v1::PointerEvent> pointers_;  // as they came
  std::uint64_t last_event_ = 0;
  v1::Frame pending_;
};

struct Fixture {
  std::shared_ptr<FakeServer> server = std::make_shared<FakeServer>();
  std::mutex mutex;
  std::vector<std::string> said;
  int locals_started = 0;
  std::weak_ptr<FakeFluid> local;    // the last fluid started here, while anyone holds it
  std::weak_ptr<FakeFluid> remote;   // the server's last stream, while anyone holds it
  v1::Hello local_hello;             // and what it was started with
  int connects = 0;                  // attempts, answered or not
  // A fluid starting here waits while this holds (a start that takes seconds: Vulkan, shaders).
  std::mutex start_mutex;
  std::condition_variable start_released;
  bool holds_local_start = false;

  void hold_local_start(bool hold) {
    {
      const std::lock_guard lock(start_mutex);
      holds_local_start = hold;
    }
    start_released.notify_all();
  }

  int locals() {
    const std::lock_guard lock(mutex);
    return locals_started;
  }
  std::shared_ptr<FakeFluid> local_fluid() {
    const std::lock_guard lock(mutex);
    return local.lock();
  }
  std::shared_ptr<FakeFluid> remote_fluid() {
    const std::lock_guard lock(mutex);
    return remote.lock();
  }
  std::vector<v1::Hello> hellos_answered() {
    const std::lock_guard lock(server->mutex);
    return server->hellos;
  }
  HandoffSides sides() {
    return {"fake:1",
            [this, server = server](const v1::Hello& hello,
                                    std::stop_token closing) -> std::shared_ptr<FluidStream> {
              {
                const std::lock_guard lock(mutex);
                ++connects;
              }
              std::unique_lock lock(server->mutex);
              if (server->hangs) {
                server->connecting = true;
                std::condition_variable_any().wait_for(lock, closing, std::chrono::seconds(30),
                                                       [] { return false; });
                server->connecting = false;
                throw Unreachable("no server answered");
              }
              if (!server->up) throw Unreachable("no server answered");
              if (hello.create().scene() == "refused") throw std::invalid_argument("no such scene");
              if (hello.has_resume() && server->forgets_sessions) {
                throw Forgotten("Hello.resume.key: that viewer has been forgotten");
              }
              if (hello.has_resume() && server->full_for > 0) {
                --server->full_for;
                throw std::runtime_error("the session has its limit of viewers");
              }
              ++server->streams;
              server->hellos.push_back(hello);
              auto fluid = std::make_shared<FakeFluid>(server, hello);
              const std::lock_guard held(mutex);
              remote = fluid;
              return fluid;
            },
            [this](const v1::Hello& hello) -> std::shared_ptr<FluidStream> {
              {
                std::unique_lock held(start_mutex);
                start_released.wait(held, [this] { return !holds_local_start; });
              }
              const std::lock_guard lock(mutex);
              ++locals_started;
              auto fluid = std::make_shared<FakeFluid>(nullptr, hello);
              local = fluid;
              local_hello = hello;
              return fluid;
            }};
  }
  HandoffOptions options() {
    HandoffOptions options;
    options.snapshot_every = milliseconds(20);
    options.retry_every = milliseconds(50);
    options.stall_after = std::chrono::seconds(2);  // no false alarm on a slow machine
    options.say = [this](const std::string& line) {
      const std::lock_guard lock(mutex);
      said.push_back(line);
    };
    return options;
  }
  void set(bool FakeServer::*field, bool value) {
    {
      const std::lock_guard lock(server->mutex);
      server.get()->*field = value;
    }
    server->released.notify_all();
  }
  bool is(bool FakeServer::*field) {
    const std::lock_guard lock(server->mutex);
    return server.get()->*field;
  }
  int connects_tried() {
    const std::lock_guard lock(mutex);
    return connects;
  }
  int snapshots_taken() {
    const std::lock_guard lock(server->mutex);
    return server->snapshots;
  }
  bool heard(const std::string& part) {
    const std::lock_guard lock(mutex);
    for (const std::string& line : said) {
      if (line.find(part) != std::string::npos) return true;
    }
    return false;
  }
};

v1::Hello hello_for(std::uint32_t particles) {
  v1::Hello hello;
  hello.mutable_create()->set_particles(particles);
  return hello;
}

// Reads frames for `time`; returns their clocks.
std::vector<float> read_for(HandoffStream& stream, milliseconds time) {
  std::vector<float> clocks;
  const auto end = std::chrono::steady_clock::now() + time;
  while (std::chrono::steady_clock::now() < end) {
    if (const auto frame = stream.next_frame(milliseconds(2))) clocks.push_back(frame->sim_time());
  }
  return clocks;
}

// Reads frames until `done` holds (at most 5 s); returns the clocks read meanwhile.
template <typename Done>
std::vector<float> read_until(HandoffStream& stream, Done done) {
  std::vector<float> clocks;
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  while (!done() && std::chrono::steady_clock::now() < end) {
    if (const auto frame = stream.next_frame(milliseconds(2))) clocks.push_back(frame->sim_time());
  }
  EXPECT_TRUE(done()) << "not within 5 s; status: " << stream.status();
  return clocks;
}

// Whether a frame later than `after` comes within 5 s: the fluid shown goes on, however slowly
// frames come on a loaded machine.
bool goes_on_after(HandoffStream& stream, float after) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  while (std::chrono::steady_clock::now() < end) {
    const auto frame = stream.next_frame(milliseconds(2));
    if (frame && frame->sim_time() > after) return true;
  }
  return false;
}

// Streams until the server has given a few snapshots (the newest state is kept) and the warm local
// fluid has started; returns the clocks read meanwhile.
std::vector<float> stream_until_kept(HandoffStream& stream, Fixture& f) {
  std::vector<float> clocks =
      read_until(stream, [&] { return f.snapshots_taken() >= 3 && f.locals() >= 1; });
  const std::vector<float> more = read_for(stream, milliseconds(50));
  clocks.insert(clocks.end(), more.begin(), more.end());
  return clocks;
}

TEST(HandoffStream, ADroppedServersFluidContinuesHereFromItsNewestState) {
  Fixture f;
  HandoffStream stream(hello_for(1000), f.sides(), f.options());
  EXPECT_FALSE(stream.simulating_here());
  const std::vector<float> streamed = stream_until_kept(stream, f);
  ASSERT_FALSE(streamed.empty());
  EXPECT_EQ(f.locals(), 1) << "a warm local fluid waits while streaming";

  f.set(&FakeServer::up, false);
  const float last_streamed = streamed.back();
  std::vector<float> here = read_until(stream, [&] { return stream.simulating_here(); });
  const std::vector<float> more = read_for(stream, milliseconds(100));
  here.insert(here.end(), more.begin(), more.end());
  ASSERT_FALSE(here.empty()) << "no frame after the handoff";
  // The fluid goes on from a snapshot a few frames behind the last one streamed; a fresh fluid,
  // or the warm one's frame from before the state went in, would be at t = 0.
  for (const float t : here) EXPECT_GT(t, last_streamed / 2) << "a frame from before";
  EXPECT_NE(stream.status().find("continuing locally"), std::string::npos) << stream.status();
  EXPECT_TRUE(goes_on_after(stream, here.back())) << "the warm fluid's pause outlived the handoff";
  ASSERT_TRUE(stream.handoff_gap_ms());
  EXPECT_LT(*stream.handoff_gap_ms(), 1000.0);
  EXPECT_TRUE(f.heard("handoff gap"));
}

// Latency counts what the user sent, on either side: not the warm fluid's pause, sent long
// before the handoff and answered only after it.
TEST(HandoffStream, LatencyCountsTheUsersEventsOnEitherSide) {
  Fixture f;
  HandoffStream stream(hello_for(1000), f.sides(), f.options());
  stream.tilt(0, -9.81f, 0);
  stream_until_kept(stream, f);
  f.set(&FakeServer::up, false);
  read_until(stream, [&] { return stream.simulating_here(); });
  stream.tilt(0, -9.81f, 0);
  read_for(stream, milliseconds(50));
  const std::vector<double> latencies = stream.latencies_ms();
  ASSERT_EQ(latencies.size(), 2u);
  for (const double ms : latencies) EXPECT_LT(ms, 250.0);
}

// A server that goes while the warm fluid is still starting (within seconds of the first frame):
// the fluid goes on here once started, and no call waits for the start meanwhile (a window goes
// on drawing and answering its close button).
TEST(HandoffStream, AServerGoneBeforeTheWarmFluidStartedHoldsNoCallUp) {
  Fixture f;
  f.hold_local_start(true);
  HandoffStream stream(hello_for(1000), f.sides(), f.options());
  read_until(stream, [&] { return f.snapshots_taken() >= 3; });
  f.set(&FakeServer::up, false);
  std::thread starts([&] {
    std::this_thread::sleep_for(milliseconds(800));
    f.hold_local_start(false);
  });
  auto longest = std::chrono::steady_clock::duration::zero();
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  bool pressed = false;
  while (!stream.simulating_here() && std::chrono::steady_clock::now() < end) {
    const auto call = std::chrono::steady_clock::now();
    stream.next_frame(milliseconds(2));
    longest = std::max(longest, std::chrono::steady_clock::now() - call);
    if (!pressed && f.heard("starting the fluid here")) {  // a finger down while it starts
      stream.pointer(2, v1::PointerEvent::DOWN, 0.3f, 0.6f);
      stream.pointer(2, v1::PointerEvent::MOVE, 0.35f, 0.6f);
      pressed = true;
    }
  }
  starts.join();
  ASSERT_TRUE(stream.simulating_here()) << stream.status();
  ASSERT_TRUE(pressed);
  EXPECT_LT(longest, milliseconds(400)) << "a call waited for the fluid's start (800 ms)";
  EXPECT_TRUE(f.heard("starting the fluid here"));
  EXPECT_TRUE(goes_on_after(stream, 0.0f));
  const std::shared_ptr<FakeFluid> here = f.local_fluid();
  ASSERT_TRUE(here);
  EXPECT_GT(here->loaded_from(), 0.0) << "it went on from the server's state";
  const std::vector<v1::PointerEvent> pointers = here->pointers();
  ASSERT_FALSE(pointers.empty()) << "the finger pressed while it started was lost";
  EXPECT_EQ(pointers.back().phase(), v1::PointerEvent::DOWN);
  EXPECT_EQ(pointers.back().pointer_id(), 2u);
  EXPECT_FLOAT_EQ(pointers.back().x(), 0.35f) << "where it was last";
}

// The fluid handed back to the server waits warm for the next handoff: nothing starts again.
TEST(HandoffStream, TheFluidHandedBackWaitsWarmForTheNextHandoff) {
  Fixture f;
  HandoffStream stream(hello_for(1000), f.sides(), f.options());
  stream_until_kept(stream, f);
  f.set(&FakeServer::up, false);
  read_until(stream, [&] { return stream.simulating_here(); });
  const std::shared_ptr<FakeFluid> warm = f.local_fluid();
  stream.pointer(3, v1::PointerEvent::DOWN, 0.4f, 0.5f);  // held down across the handback
  f.set(&FakeServer::up, true);
  read_until(stream, [&] { return !stream.simulating_here(); });
  ASSERT_FALSE(warm->pointers().empty());
  EXPECT_EQ(warm->pointers().back().phase(), v1::PointerEvent::CANCEL)
      << "the finger stays down in the waiting fluid";
  const int snapshots = f.snapshots_taken();
  const float streamed =
      read_until(stream, [&] { return f.snapshots_taken() >= snapshots + 3; }).back();
  EXPECT_TRUE(warm->paused()) << "the fluid here runs on beside the server's";

  f.set(&FakeServer::up, false);
  read_until(stream, [&] { return stream.simulating_here(); });
  EXPECT_EQ(f.locals(), 1) << "a second fluid was started";
  EXPECT_TRUE(f.local_fluid() == warm) << "not the fluid handed back";
  EXPECT_GT(warm->loaded_from(), streamed / 2) << "not the newest state";
  EXPECT_TRUE(goes_on_after(stream, warm->loaded_from())) << "still paused";
}

// The fluid goes back into the session it left (others watching it stay with it).
TEST(HandoffStream, AServerThatComesBackTakesTheFluidAndStreamsAgain) {
  Fixture f;
  HandoffStream stream(hello_for(1000), f.sides(), f.options());
  stream_until_kept(stream, f);
  const std::string key = stream.welcome().access().resume_key();
  f.set(&FakeServer::up, false);
  read_until(stream, [&] { return stream.simulating_here(); });
  const std::vector<float> here = read_for(stream, milliseconds(150));
  ASSERT_FALSE(here.empty());
  const float continued = here.back();

  f.set(&FakeServer::up, true);
  read_until(stream, [&] { return !stream.simulating_here(); });
  const std::vector<float> again = read_for(stream, milliseconds(100));
  {
    const std::lock_guard lock(f.server->mutex);
    ASSERT_EQ(f.server->put.size(), 1u) << "the state here goes into the session";
    EXPECT_GE(f.server->put[0].time(), continued);
    EXPECT_EQ(f.server->streams, 2);
    EXPECT_TRUE(f.server->hellos.back().has_resume()) << "a new session was asked for";
    EXPECT_EQ(f.server->hellos.back().resume().key(), key);
    EXPECT_EQ(f.server->hellos.back().resume().session_key(), "control-key")
        << "a seat forgotten would leave the session behind";
  }
  ASSERT_FALSE(again.empty());
  for (const float t : again) EXPECT_GE(t, continued) << "a frame of the session from before";
  EXPECT_NE(stream.status().find("again"), std::string::npos) << stream.status();
  EXPECT_TRUE(f.heard("the server is back and took the state (1000 particles"));
  EXPECT_TRUE(f.heard("into the session it left"));
  EXPECT_TRUE(f.heard("first frame streamed after the handoff"));
}

// Streams, loses the server, goes on here for a while, and lets it back having forgotten the
// session (it restarted) or refusing its resume once (`refused_resume`): the fluid goes into a
// new session of its scene and count.
void hand_back_into_a_new_session(bool refused_resume) {
  Fixture f;
  HandoffStream stream(hello_for(1000), f.sides(), f.options());
  stream_until_kept(stream, f);
  f.set(&FakeServer::up, false);
  read_until(stream, [&] { return stream.simulating_here(); });
  const float continued = read_for(stream, milliseconds(100)).back();
  {
    const std::lock_guard lock(f.server->mutex);
    f.server->full_for = refused_resume ? 1 : 0;
  }
  f.set(&FakeServer::forgets_sessions, !refused_resume);
  f.set(&FakeServer::up, true);
  read_until(stream, [&] { return !stream.simulating_here(); });
  EXPECT_TRUE(f.heard(refused_resume ? "refused a session" : "no longer has the session"));
  EXPECT_TRUE(f.heard("into a new session"));
  const std::lock_guard lock(f.server->mutex);
  ASSERT_EQ(f.server->hellos.size(), 2u);
  const v1::Hello& back = f.server->hellos.back();
  EXPECT_FALSE(back.has_resume());
  EXPECT_EQ(back.create().particles(), 1000u);
  ASSERT_EQ(f.server->put.size(), 1u);
  EXPECT_GE(f.server->put[0].time(), continued);
}

TEST(HandoffStream, AFluidWhoseSessionIsForgottenGoesIntoANewOne) {
  hand_back_into_a_new_session(false);
}

// A resume refused (its seat taken, say) is not asked again while the fluid goes on here: it
// needs no old seat.
TEST(HandoffStream, AFluidWhoseResumeIsRefusedGoesIntoANewSession) {
  hand_back_into_a_new_session(true);
}

TEST(HandoffStream, ASilentStreamCountsAsLost) {
  Fixture f;
  HandoffOptions options = f.options();
  options.stall_after = milliseconds(300);
  HandoffStream stream(hello_for(1000), f.sides(), options);
  stream_until_kept(stream, f);
  f.set(&FakeServer::silent, true);
  read_until(stream, [&] { return stream.simulating_here(); });
  EXPECT_NE(stream.status().find("nothing came for 300 ms"), std::string::npos) << stream.status();
}

// A session that does not continue here is the server's to keep for a while: a blip of the
// network brings back the same fluid, gone on there, rather than a new one from the start.
TEST(HandoffStream, ASessionTooBigToSimulateHereIsResumed) {
  Fixture f;
  HandoffOptions options = f.options();
  options.max_local_particles = 500;
  HandoffStream stream(hello_for(1000), f.sides(), options);
  read_for(stream, milliseconds(200));
  EXPECT_EQ(f.locals(), 0) << "no warm fluid for a session that cannot continue here";
  const std::string key = stream.welcome().access().resume_key();
  ASSERT_FALSE(key.empty());
  f.set(&FakeServer::up, false);
  read_until(stream, [&] { return stream.status().find("gone") != std::string::npos; });
  EXPECT_FALSE(stream.simulating_here());
  EXPECT_NE(stream.status().find("too big to continue here (1000 particles)"), std::string::npos)
      << stream.status();
  {  // refused twice for a reason that passes: the resume is asked again, not a new session
    const std::lock_guard lock(f.server->mutex);
    f.server->full_for = 2;
  }
  f.set(&FakeServer::up, true);
  read_until(stream, [&] { return f.hellos_answered().size() == 2; });
  EXPECT_TRUE(f.heard("refused a session"));
  const v1::Hello back = f.hellos_answered().back();
  EXPECT_TRUE(back.has_resume()) << "a new session was asked for";
  EXPECT_EQ(back.resume().key(), key);
  const std::lock_guard lock(f.server->mutex);
  EXPECT_TRUE(f.server->put.empty()) << "nothing continued, nothing to put back";
}

// A server that no longer has the session (it restarted) is asked for a new one, as first.
TEST(HandoffStream, AResumeTheServerRefusesAsksForANewSession) {
  Fixture f;
  HandoffOptions options = f.options();
  options.max_local_particles = 500;
  HandoffStream stream(hello_for(1000), f.sides(), options);
  read_for(stream, milliseconds(100));
  f.set(&FakeServer::up, false);
  read_until(stream, [&] { return stream.status().find("gone") != std::string::npos; });
  f.set(&FakeServer::forgets_sessions, true);
  f.set(&FakeServer::up, true);
  // The server answers the Hello before this thread takes the stream: streaming says both.
  read_until(stream, [&] { return stream.status().find("streaming") != std::string::npos; });
  EXPECT_TRUE(f.heard("no longer has the session"));
  ASSERT_EQ(f.hellos_answered().size(), 2u);
  const v1::Hello back = f.hellos_answered().back();
  EXPECT_FALSE(back.has_resume());
  EXPECT_EQ(back.create().particles(), 1000u);
}

TEST(HandoffStream, AWatcherDoesNotContinueSomeoneElsesFluid) {
  Fixture f;
  f.set(&FakeServer::viewers_control, false);
  HandoffStream stream(hello_for(1000), f.sides(), f.options());
  read_for(stream, milliseconds(200));
  f.set(&FakeServer::up, false);
  read_until(stream, [&] { return stream.status().find("retrying") != std::string::npos; });
  EXPECT_FALSE(stream.simulating_here());
  EXPECT_EQ(f.locals(), 0);
  // Back, it asks for its seat, or a new one with the key it was given (the view key).
  f.set(&FakeServer::up, true);
  read_until(stream, [&] { return f.hellos_answered().size() == 2; });
  const v1::Hello back = f.hellos_answered().back();
  ASSERT_TRUE(back.has_resume());
  EXPECT_EQ(back.resume().session_key(), "view-key");
  EXPECT_FALSE(back.resume().has_state());
}

TEST(HandoffStream, WithoutHandoffAServerThatDoesNotAnswerIsAnError) {
  Fixture f;
  f.set(&FakeServer::up, false);
  HandoffOptions options = f.options();
  options.handoff = false;
  EXPECT_THROW(HandoffStream(hello_for(1000), f.sides(), options), Unreachable);
}

TEST(HandoffStream, ARefusalAtTheStartStands) {
  Fixture f;
  v1::Hello hello = hello_for(1000);
  hello.mutable_create()->set_scene("refused");
  EXPECT_THROW(HandoffStream(hello, f.sides(), f.options()), std::invalid_argument);
}

TEST(HandoffStream, WithHandoffAServerThatDoesNotAnswerYetIsAskedAgain) {
  Fixture f;
  f.set(&FakeServer::up, false);
  HandoffStream stream(hello_for(1000), f.sides(), f.options());
  EXPECT_NE(stream.status().find("cannot connect"), std::string::npos);
  EXPECT_EQ(stream.send({}), 0u) << "no stream, nothing sent";
  EXPECT_FALSE(stream.next_frame(milliseconds(5)));
  f.set(&FakeServer::up, true);
  read_until(stream, [&] { return stream.welcome().session_id() == "remote"; });
  EXPECT_EQ(stream.status(), "streaming from fake:1");
}

// A stream that goes while it asks the server again waits for no answer: a window closed during
// an outage closes at once, not when the connection being made gives up (5 s).
TEST(HandoffStream, GoingWhileAskingTheServerAgainWaitsForNoAnswer) {
  Fixture f;
  auto stream = std::make_unique<HandoffStream>(hello_for(0), f.sides(), f.options());
  stream_until_kept(*stream, f);
  f.set(&FakeServer::hangs, true);
  f.set(&FakeServer::up, false);
  read_until(*stream, [&] { return stream->simulating_here() && f.is(&FakeServer::connecting); });
  ASSERT_TRUE(f.is(&FakeServer::connecting));
  const auto going = std::chrono::steady_clock::now();
  stream.reset();
  EXPECT_LT(std::chrono::steady_clock::now() - going, std::chrono::seconds(2));
}

TEST(HandoffStream, ANewStreamOpensWithTheNewestViewport) {
  Fixture f;
  f.server->particles = 1500;  // the server's choice: the Hello names no count
  std::vector<v1::Hello> hellos;
  HandoffSides sides = f.sides();
  sides.connect = [&, connect = sides.connect](const v1::Hello& hello, std::stop_token closing) {
    auto opened = connect(hello, closing);  // one retry at a time: no two threads push at once
    hellos.push_back(hello);
    return opened;
  };
  HandoffStream stream(hello_for(0), sides, f.options());
  v1::Command resize;
  resize.mutable_viewport()->set_width(640);
  stream.command(resize);
  stream_until_kept(stream, f);
  f.set(&FakeServer::up, false);
  read_until(stream, [&] { return stream.simulating_here(); });
  f.set(&FakeServer::forgets_sessions, true);  // a new session: the Hello names the count
  f.set(&FakeServer::up, true);
  read_until(stream, [&] { return !stream.simulating_here(); });
  ASSERT_EQ(hellos.size(), 2u);
  EXPECT_EQ(hellos[1].viewport().width(), 640u);
  EXPECT_EQ(hellos[1].create().particles(), 1500u) << "the fluid's count goes with it";
}

TEST(HandoffStream, WithoutRetryTheStreamEndsWithTheServerUnlessItContinuesHere) {
  Fixture f;
  HandoffOptions options = f.options();
  options.handoff = options.retry = false;
  HandoffStream stream(hello_for(1000), f.sides(), options);
  read_for(stream, milliseconds(100));
  EXPECT_FALSE(stream.ended());
  f.set(&FakeServer::up, false);
  read_until(stream, [&] { return stream.ended(); });
  EXPECT_NE(stream.end_reason().find("the server went away"), std::string::npos);
  EXPECT_NE(stream.close(), "") << "it did not end well";
  EXPECT_EQ(f.locals(), 0);

  f.set(&FakeServer::up, true);
  options.handoff = true;
  HandoffStream continued(hello_for(1000), f.sides(), options);
  stream_until_kept(continued, f);
  f.set(&FakeServer::up, false);
  read_until(continued, [&] { return continued.simulating_here(); });
  EXPECT_FALSE(continued.ended());
  EXPECT_EQ(continued.status().find("retrying"), std::string::npos) << continued.status();
  EXPECT_EQ(continued.close(), "");
}

// A stream the server ends on purpose (here: an idle session) is not a loss: its reason stands,
// nothing continues here and nothing asks again.
TEST(HandoffStream, AStreamTheServerEndsOnPurposeEndsThisOne) {
  Fixture f;
  HandoffStream stream(hello_for(1000), f.sides(), f.options());
  stream_until_kept(stream, f);
  ASSERT_TRUE(f.local_fluid()) << "a warm local fluid waits while streaming";
  f.set(&FakeServer::ends_streams, true);
  read_until(stream, [&] { return stream.ended(); });
  // Nothing will carry the fluid on: the warm one is let go of, though a snapshot request may
  // still be on its way.
  read_until(stream, [&] { return !f.local_fluid(); });
  read_for(stream, milliseconds(200));
  EXPECT_FALSE(stream.simulating_here());
  EXPECT_EQ(stream.status(), "the server ended the stream: nobody touched the fluid");
  EXPECT_EQ(stream.close(), "nobody touched the fluid");
  const std::lock_guard lock(f.server->mutex);
  EXPECT_EQ(f.server->streams, 1) << "not asked again";
}

// A server that comes back but refuses the fluid here leaves it here, going on, and is asked
// again; once it takes it, the stream goes on from the fluid's clock, not a new session's.
TEST(HandoffStream, AServerThatRefusesTheFluidLeavesItHere) {
  Fixture f;
  HandoffStream stream(hello_for(1000), f.sides(), f.options());
  stream_until_kept(stream, f);
  f.set(&FakeServer::up, false);
  read_until(stream, [&] { return stream.simulating_here(); });
  const std::shared_ptr<FakeFluid> local = f.local_fluid();
  ASSERT_TRUE(local);
  const double started_from = local->loaded_from();
  EXPECT_GT(started_from, 0.0) << "the fluid here did not start from the server's state";
  f.set(&FakeServer::refuses_states, true);
  f.set(&FakeServer::up, true);
  read_until(stream, [&] { return stream.status().find("refused") != std::string::npos; });
  EXPECT_TRUE(stream.simulating_here());
  EXPECT_NE(stream.status().find("particle 7 is outside"), std::string::npos) << stream.status();
  const std::vector<float> here = read_for(stream, milliseconds(100));
  ASSERT_FALSE(here.empty());
  EXPECT_EQ(local->loaded_from(), started_from) << "the fluid here was loaded again";
  EXPECT_GE(here.front(), static_cast<float>(started_from))  // frames carry floats
      << "the fluid here went on, not from the start";
  EXPECT_TRUE(goes_on_after(stream, here.back())) << "the fluid here was left paused";
  f.set(&FakeServer::refuses_states, false);
  read_until(stream, [&] { return !stream.simulating_here(); });
  const std::vector<float> back = read_for(stream, milliseconds(100));
  ASSERT_FALSE(back.empty());
  EXPECT_GE(back.front(), here.back());
}

// Streams, loses the server, goes on here, and lets the server back refusing the fluid here;
// returns once the refusal is told.
void refused_on_its_return(HandoffStream& stream, Fixture& f) {
  stream_until_kept(stream, f);
  f.set(&FakeServer::up, false);
  read_until(stream, [&] { return stream.simulating_here(); });
  f.set(&FakeServer::refuses_states, true);
  f.set(&FakeServer::up, true);
  read_until(stream, [&] { return stream.status().find("refused") != std::string::npos; });
}

// A stream that came back but did not take the fluid says goodbye, so that the server keeps no
// seat for it (nor a session nobody watches); a server slow to answer that holds nothing here.
TEST(HandoffStream, AStreamThatDidNotTakeTheFluidSaysGoodbyeWithoutHoldingItUp) {
  Fixture f;
  HandoffStream stream(hello_for(1000), f.sides(), f.options());
  f.set(&FakeServer::holds_goodbyes, true);
  refused_on_its_return(stream, f);
  const std::vector<float> here = read_for(stream, milliseconds(100));
  ASSERT_FALSE(here.empty());
  EXPECT_TRUE(goes_on_after(stream, here.back())) << "the fluid here waited for the goodbye";
  f.set(&FakeServer::holds_goodbyes, false);
  f.set(&FakeServer::refuses_states, false);
  read_until(stream, [&] { return !stream.simulating_here(); });
  read_until(stream, [&] {  // the goodbyes' threads, released, finish
    const std::lock_guard lock(f.server->mutex);
    return f.server->goodbyes >= f.server->streams - 2;
  });
  const std::lock_guard lock(f.server->mutex);
  EXPECT_GE(f.server->streams, 3);
  EXPECT_EQ(f.server->goodbyes, f.server->streams - 2)
      << "each stream that did not take the fluid says goodbye (the lost one and the one "
         "streaming do not)";
}

// A fluid its viewer paused stays paused through the handback: here while a server refuses it,
// and in the new session once one takes it.
TEST(HandoffStream, APausedFluidStaysPausedAcrossTheHandback) {
  Fixture f;
  HandoffStream stream(hello_for(1000), f.sides(), f.options());
  v1::Command pause;
  pause.set_pause(true);
  stream.command(pause);
  refused_on_its_return(stream, f);
  const std::shared_ptr<FakeFluid> local = f.local_fluid();
  ASSERT_TRUE(local);
  EXPECT_TRUE(local->paused()) << "a refused handback set the fluid here going";
  f.set(&FakeServer::refuses_states, false);
  read_until(stream, [&] { return !stream.simulating_here(); });
  const std::shared_ptr<FakeFluid> remote = f.remote_fluid();
  ASSERT_TRUE(remote);
  EXPECT_TRUE(remote->paused()) << "the new session runs what its viewer paused";
}

// A fluid that went on here goes on in the session it goes back to, though that was left paused.
TEST(HandoffStream, AFluidGoingOnHereGoesOnInThePausedSessionItGoesBackTo) {
  Fixture f;
  HandoffStream stream(hello_for(1000), f.sides(), f.options());
  stream_until_kept(stream, f);
  f.set(&FakeServer::up, false);
  read_until(stream, [&] { return stream.simulating_here(); });
  f.set(&FakeServer::resumes_paused, true);
  f.set(&FakeServer::up, true);
  read_until(stream, [&] { return !stream.simulating_here(); });
  const std::shared_ptr<FakeFluid> remote = f.remote_fluid();
  ASSERT_TRUE(remote);
  EXPECT_TRUE(f.hellos_answered().back().has_resume());
  EXPECT_FALSE(remote->paused()) << "the fluid handed back stopped";
}

// A pause another viewer asked of the session holds for this viewer too: the fluid continued here
// stays as the session last showed it, and once that viewer set it going again, goes on.
TEST(HandoffStream, APauseAnotherViewerAskedHoldsForTheFluidContinuedHere) {
  Fixture f;
  HandoffStream stream(hello_for(1000), f.sides(), f.options());
  stream_until_kept(stream, f);
  std::shared_ptr<FakeFluid> remote = f.remote_fluid();
  ASSERT_TRUE(remote);
  remote->paused_by_another(true);
  read_for(stream, milliseconds(50));
  f.set(&FakeServer::up, false);
  read_until(stream, [&] { return stream.simulating_here(); });
  std::shared_ptr<FakeFluid> local = f.local_fluid();
  ASSERT_TRUE(local);
  EXPECT_TRUE(local->paused()) << "the fluid here ran what the session showed paused";

  f.set(&FakeServer::up, true);
  read_until(stream, [&] { return !stream.simulating_here(); });
  remote = f.remote_fluid();
  ASSERT_TRUE(remote);
  EXPECT_TRUE(remote->paused());
  remote->paused_by_another(false);
  stream_until_kept(stream, f);
  f.set(&FakeServer::up, false);
  read_until(stream, [&] { return stream.simulating_here(); });
  local = f.local_fluid();
  ASSERT_TRUE(local);
  EXPECT_FALSE(local->paused()) << "a pause another viewer ended held here";
}

// A pause this viewer sent holds for the fluid continued here even when the server went before
// its session showed it.
TEST(HandoffStream, APauseNotYetShownHoldsForTheFluidContinuedHere) {
  Fixture f;
  HandoffStream stream(hello_for(1000), f.sides(), f.options());
  stream_until_kept(stream, f);
  v1::Command pause;
  pause.set_pause(true);
  stream.command(pause);
  stream.next_frame(milliseconds(2));  // a frame from before the pause
  f.set(&FakeServer::up, false);
  read_until(stream, [&] { return stream.simulating_here(); });
  const std::shared_ptr<FakeFluid> local = f.local_fluid();
  ASSERT_TRUE(local);
  EXPECT_TRUE(local->paused()) << "a pause the session had not shown yet was lost";
}

// A finger held down as the server goes stirs the fluid here: the local fluid is told it went
// down, where it was last.
TEST(HandoffStream, AFingerHeldDownGoesOnStirringAcrossAHandoff) {
  Fixture f;
  HandoffStream stream(hello_for(1000), f.sides(), f.options());
  stream_until_kept(stream, f);
  stream.pointer(1, v1::PointerEvent::DOWN, 0.5f, 0.5f);
  stream.pointer(1, v1::PointerEvent::MOVE, 0.6f, 0.4f);
  stream.pointer(2, v1::PointerEvent::DOWN, 0.1f, 0.1f);
  stream.pointer(2, v1::PointerEvent::UP, 0.1f, 0.1f);
  f.set(&FakeServer::up, false);
  read_until(stream, [&] { return stream.simulating_here(); });
  const std::shared_ptr<FakeFluid> local = f.local_fluid();
  ASSERT_TRUE(local);
  const std::vector<v1::PointerEvent> pressed = local->pointers();
  ASSERT_EQ(pressed.size(), 1u) << "a lifted finger went down here, or the held one did not";
  EXPECT_EQ(pressed[0].pointer_id(), 1u);
  EXPECT_EQ(pressed[0].phase(), v1::PointerEvent::DOWN);
  EXPECT_FLOAT_EQ(pressed[0].x(), 0.6f);
  EXPECT_FLOAT_EQ(pressed[0].y(), 0.4f);
}

// Streams, loses the server, goes on here with a finger down at (0.5, 0.5), and lets the server
// back with its loads held (refusing them, if `refused`): the handback waits with the fluid here
// paused. Returns the fluid here.
std::shared_ptr<FakeFluid> handback_under_way(HandoffStream& stream, Fixture& f, bool refused) {
  stream_until_kept(stream, f);
  f.set(&FakeServer::up, false);
  read_until(stream, [&] { return stream.simulating_here(); });
  std::shared_ptr<FakeFluid> local = f.local_fluid();
  stream.pointer(1, v1::PointerEvent::DOWN, 0.5f, 0.5f);
  f.set(&FakeServer::holds_loads, true);
  f.set(&FakeServer::refuses_states, refused);
  f.set(&FakeServer::up, true);
  read_until(stream, [&] { return f.is(&FakeServer::load_waiting); });
  return local;
}

// What the user does while the fluid's state goes back to the server (the fluid here paused)
// reaches the session it goes on in, after the finger held down goes down there; the paused
// fluid here gets none of it.
TEST(HandoffStream, WhatTheUserDoesDuringAHandbackReachesTheSessionItGoesTo) {
  Fixture f;
  HandoffStream stream(hello_for(1000), f.sides(), f.options());
  const std::shared_ptr<FakeFluid> local = handback_under_way(stream, f, false);
  ASSERT_TRUE(local);
  for (int k = 0; k <= 10; ++k) stream.pointer(1, v1::PointerEvent::MOVE, 0.6f + 0.01f * k, 0.2f);
  f.set(&FakeServer::holds_loads, false);
  read_until(stream, [&] { return !stream.simulating_here(); });
  const std::shared_ptr<FakeFluid> remote = f.remote_fluid();
  ASSERT_TRUE(remote);
  const std::vector<v1::PointerEvent> here = local->pointers();
  ASSERT_EQ(here.size(), 2u) << "the paused fluid here took what was held back";
  EXPECT_EQ(here[1].phase(), v1::PointerEvent::CANCEL) << "lifted as it waits for the next handoff";
  const std::vector<v1::PointerEvent> there = remote->pointers();
  ASSERT_EQ(there.size(), 2u) << "a finger's moves held back go as its newest";
  EXPECT_EQ(there[0].phase(), v1::PointerEvent::DOWN);
  EXPECT_FLOAT_EQ(there[0].x(), 0.5f);
  EXPECT_EQ(there[1].phase(), v1::PointerEvent::MOVE);
  EXPECT_FLOAT_EQ(there[1].x(), 0.7f);
}

// Refused, the handback leaves the fluid here, and what the user did meanwhile goes to it.
TEST(HandoffStream, WhatTheUserDoesDuringARefusedHandbackGoesOnHere) {
  Fixture f;
  HandoffStream stream(hello_for(1000), f.sides(), f.options());
  const std::shared_ptr<FakeFluid> local = handback_under_way(stream, f, true);
  ASSERT_TRUE(local);
  stream.pointer(1, v1::PointerEvent::MOVE, 0.7f, 0.2f);
  EXPECT_EQ(local->pointers().size(), 1u) << "the paused fluid here took it at once";
  f.set(&FakeServer::holds_loads, false);
  read_until(stream, [&] { return stream.status().find("refused") != std::string::npos; });
  const std::vector<v1::PointerEvent> here = local->pointers();
  ASSERT_EQ(here.size(), 2u);
  EXPECT_EQ(here[1].phase(), v1::PointerEvent::MOVE);
  EXPECT_FLOAT_EQ(here[1].x(), 0.7f);
  EXPECT_TRUE(stream.simulating_here());
}

TEST(HandoffStream, LocalModeNeedsNoServer) {
  Fixture f;
  f.set(&FakeServer::up, false);
  HandoffOptions options = f.options();
  options.local = true;
  HandoffStream stream(hello_for(1000), f.sides(), options);
  EXPECT_TRUE(stream.simulating_here());
  const std::vector<float> clocks = read_for(stream, milliseconds(100));
  ASSERT_GT(clocks.size(), 10u);
  EXPECT_GT(clocks.back(), clocks.front());
  EXPECT_EQ(f.server->streams, 0);
  f.set(&FakeServer::up, true);  // nor asks one that is there, for several retry intervals
  read_for(stream, 4 * options.retry_every);
  EXPECT_TRUE(stream.simulating_here());
  EXPECT_EQ(f.connects_tried(), 0);
}

// The fluid that goes on here is as its viewer left it: paused if they paused it, at the size they
// last asked for; and the warm one waits at one frame a second.
TEST(HandoffStream, AFluidContinuedHereIsAsItsViewerLeftIt) {
  Fixture f;
  HandoffStream stream(hello_for(1000), f.sides(), f.options());
  v1::Command pause;
  pause.set_pause(true);
  stream.command(pause);
  v1::Command resize;
  resize.mutable_viewport()->set_width(320);
  resize.mutable_viewport()->set_height(240);
  stream.command(resize);
  stream_until_kept(stream, f);
  {
    const std::lock_guard lock(f.mutex);
    EXPECT_EQ(f.local_hello.quality().max_fps(), 1u) << "the warm fluid renders at full rate";
  }
  resize.mutable_viewport()->set_width(640);  // after the warm fluid started: the newest size
  stream.command(resize);
  f.set(&FakeServer::up, false);
  read_until(stream, [&] { return stream.simulating_here(); });
  const std::shared_ptr<FakeFluid> local = f.local_fluid();
  ASSERT_TRUE(local);
  EXPECT_TRUE(local->paused());
  EXPECT_EQ(local->viewport_width(), 640u);
  EXPECT_EQ(f.locals(), 1) << "the warm fluid is the one that goes on";
}

// While streaming, snapshots come every snapshot_every, not with every frame; while the server is
// gone it is asked again every retry_every, not with every frame. The bounds hold however loaded
// the machine: in n intervals at most n requests start, one more may be in flight as the count
// starts and one start as it ends; load can only make fewer, or the same take longer.
TEST(HandoffStream, SnapshotsAndRetriesKeepTheirIntervals) {
  Fixture f;
  const HandoffOptions options = f.options();
  HandoffStream stream(hello_for(1000), f.sides(), options);
  stream_until_kept(stream, f);
  const int before = f.snapshots_taken();
  read_for(stream, 10 * options.snapshot_every);
  EXPECT_LE(f.snapshots_taken() - before, 10 + 2);
  f.set(&FakeServer::up, false);
  read_until(stream, [&] { return stream.simulating_here(); });
  int tried = f.connects_tried();
  read_for(stream, 6 * options.retry_every);
  EXPECT_LE(f.connects_tried() - tried, 6 + 2);
  tried = f.connects_tried();
  const auto from = std::chrono::steady_clock::now();
  read_until(stream, [&] { return f.connects_tried() - tried >= 4; });
  EXPECT_GE(std::chrono::steady_clock::now() - from, 2 * options.retry_every);
}

// A session of exactly the most particles simulated here still continues here.
TEST(HandoffStream, ASessionAtTheLocalLimitContinuesHere) {
  Fixture f;
  HandoffOptions options = f.options();
  options.max_local_particles = 1000;
  HandoffStream stream(hello_for(1000), f.sides(), options);
  stream_until_kept(stream, f);
  EXPECT_EQ(f.locals(), 1) << "no warm fluid for a session at the limit";
  f.set(&FakeServer::up, false);
  read_until(stream, [&] { return stream.simulating_here(); });
  EXPECT_TRUE(stream.simulating_here());
}

}  // namespace
}  // namespace fluidcast::client

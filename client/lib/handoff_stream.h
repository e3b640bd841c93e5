// A server's fluid that carries on here when the server goes, and goes back when it returns: the
// remote↔local handoff, for any client.
//
// While it streams a session small enough to simulate here (and may change it: a watcher's copy
// is not continued), it keeps the session's newest state, fetched on the side every
// snapshot_every, and a local fluid warm: started, paused, each state put in as it arrives. When
// the stream is lost (FluidStream::lost: the server or the network went away), or sends nothing
// for stall_after, the local fluid resumes from that state within a frame or two (or once it has
// started, for a server gone within seconds of streaming; no call waits for that). Meanwhile it
// asks the server again every retry_every; once one answers and takes the local fluid's state
// into the session left (resumed: others watching it stay with it) or, once the server no longer
// has that, a new one, it streams from there (a server that refuses is asked again, for a new
// session, the fluid going on here). A session that does not continue here is resumed (the same
// fluid, gone on at the server), or, once the server no longer has it, asked for anew. A stream
// the server ended on purpose (bad input, an idle session) ends this one: its reason stands.
// Frames that reflect no event since a side changed show a state from before the change: they
// are not returned.
//
// What the user does while a handback has the fluid here paused (its state going over) is held
// back and sent to whichever side the fluid goes on from; a finger held down as the fluid changes
// sides goes down on the new one too, so a drag goes on across a handoff.
//
// Touch-to-photon latency counts the events sent through it (one held back from when it was
// held), not what the handoff sends itself (pauses, the wake, markers, a held finger): those are
// no one's wait.
//
// One thread uses it; next_frame also takes the handoff's steps. The slow work (connecting,
// snapshots, starting the local fluid) runs on threads of its own, so no call waits on a server.
#pragma once

#include <chrono>
#include <functional>
#include <future>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <stop_token>
#include <string>
#include <vector>

#include "fluid_stream.h"

namespace fluidcast::client {

// What HandoffSides::connect throws when no server answered: it is asked again later.
class Unreachable : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// What HandoffSides::connect throws when the server no longer has the session a Hello resumes
// (it restarted, or nobody watched it past the grace): a new one is asked for.
class Forgotten : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The two sides a fluid moves between.
struct HandoffSides {
  std::string server;  // where connect goes, as the status line names it
  // A new stream of the server's session that this Hello asks for. Throws Unreachable when no
  // server answered, Forgotten when it no longer has the session resumed, anything else for what
  // the server refused; returns or throws soon once `closing` is requested (the HandoffStream
  // goes, and waits for it), whatever the server does.
  std::function<std::shared_ptr<FluidStream>(const v1::Hello&, std::stop_token closing)> connect;
  // A fluid simulated here; throws when it cannot start.
  std::function<std::shared_ptr<FluidStream>(const v1::Hello&)> start_local;
};

struct HandoffOptions {
  bool local = false;   // simulate here from the start, without a server
  bool handoff = true;  // continue here when the server goes
  // Ask the server again while it is gone; else the stream ends with it, unless the fluid
  // continues here.
  bool retry = true;
  std::uint32_t max_local_particles = 8000;       // larger sessions are not continued here
  std::chrono::milliseconds snapshot_every{250};  // how far back in time a handoff may go
  std::chrono::milliseconds retry_every{2000};
  // A stream that sends nothing for this long is lost (a wedged server, a dead route).
  std::chrono::milliseconds stall_after{5000};
  std::function<void(const std::string&)> say;  // what happened, in a line for the user
  // Requested by the client as it stops (Ctrl-C): a connection being made, the first one too,
  // gives up at once.
  std::stop_token stop;
};

class HandoffStream final : public FluidStream {
 public:
  // Opens the first stream: a local fluid in local mode, else the server's. Throws what opening
  // threw, except that with handoff and retry a server that did not answer (Unreachable) is asked
  // again; a refusal stands (asking again would not change it). Later, while the server is gone,
  // any failure to reconnect is asked again.
  HandoffStream(v1::Hello hello, HandoffSides sides, HandoffOptions options);
  // Waits for the work of its own threads, a connection being made given up at once.
  ~HandoffStream() override;
  HandoffStream(const HandoffStream&) = delete;
  HandoffStream& operator=(const HandoffStream&) = delete;

  const v1::Welcome& welcome() const override;  // an empty one while there is no stream
  // To the side streaming now (0 while there is none). Viewport and quality commands are also
  // what a new stream opens with.
  std::uint64_t send(v1::ClientMessage message) override;
  std::optional<v1::Frame> next_frame(std::chrono::milliseconds timeout) override;
  // A stream the server ended on purpose, a local-mode fluid that ended, or a server gone with
  // nothing continuing here and no retry.
  bool ended() const override;
  std::string end_reason() const override;
  bool lost() const override { return ended() && !server_ended_ && !options_.local; }
  std::string close() override;  // the side streaming now; else why there is none
  v1::Snapshot snapshot() override;
  void load(const v1::Snapshot& snapshot) override;

  bool simulating_here() const { return stream_ && !remote_; }
  // Where the fluid is and what is being tried, in words for the user.
  const std::string& status() const { return status_; }
  // From the last frame streamed to the first simulated here, at the newest handoff.
  std::optional<double> handoff_gap_ms() const { return handoff_gap_ms_; }

 private:
  class Standby;
  // A new stream of the server's, with the local fluid's state put into it on the same thread (a
  // state it does not take makes the reconnection fail: the fluid stays here).
  struct Reconnected {
    std::shared_ptr<FluidStream> stream;
    std::optional<v1::Snapshot> state_put;  // what went in, if a fluid here did
    bool resumed = false;                   // the session left, not a new one
  };
  using Clock = std::chrono::steady_clock;

  // To the side streaming now (none: dropped), keeping track of the pointers held down there.
  std::uint64_t deliver(v1::ClientMessage message);
  void track(const v1::PointerEvent& event, bool sent);
  // Into held_back_ (under handback_->mutex).
  void hold_back(v1::ClientMessage message);
  // A side just taken up has not seen the pointers held down go down: it is told.
  void press_held_pointers();
  // What the user did while a handback held the fluid here paused, to the side streaming now.
  void release_held_back();
  void open_first();
  FluidStream& current() const;  // the side streaming now; throws when there is none
  bool continues_here() const;
  void shown(const v1::Frame& frame);
  void keep_snapshot();
  void keep_standby();
  void ended_by_server();
  void lost(const std::string& why);
  // Once the standby in starting_here_ has started (or failed to), the fluid goes on here from
  // it; says whether that happened.
  bool continue_when_started();
  void continue_here(Standby& standby, const std::string& why);
  void reconnect();
  void came_back(Reconnected back);
  // Nothing more starts on the server's side: a reconnection in flight ends soon (its connection
  // gives up), and a stream it opened goes unused, with a goodbye rather than a drop that the
  // server keeps a seat for.
  void give_up_reconnecting();
  void set_status(std::string status);
  void say(const std::string& line) const;

  v1::Hello hello_;  // what a new stream asks for: the newest viewport and quality
  const HandoffSides sides_;
  const HandoffOptions options_;
  std::shared_ptr<FluidStream> stream_;  // null while the server is gone and nothing continues
  bool remote_ = false;
  bool server_ended_ = false;  // on purpose (a refusal, an idle session): final
  // As the streamed session last told (Welcome.state), or as this viewer last asked.
  bool paused_ = false;
  // This viewer's last pause or going on, while no frame of the streamed session reflects it yet.
  std::uint64_t pause_asked_ = 0;
  // The lost session's keys, asked for first on the way back: the server keeps this viewer's seat
  // for a while and the session while anyone watches, so a blip of the network brings back the
  // same session (with the fluid here, if one went on). Forgotten once the server no longer has
  // it, or a resume with the fluid here failed.
  std::optional<v1::Resume> resume_;
  bool streamed_before_ = false;
  std::string status_;

  // Requested as it closes or goes, or as options_.stop is: a reconnection stops waiting on the
  // server.
  std::stop_source closing_;
  struct RequestStop {
    std::stop_source* source;
    void operator()() const { source->request_stop(); }
  };
  const std::stop_callback<RequestStop> stop_when_asked_{options_.stop, RequestStop{&closing_}};
  std::future<v1::Snapshot> snapshot_request_;
  std::vector<std::future<v1::Snapshot>> abandoned_;  // requests to a lost server, still running
  // Goodbyes of streams that did not take the fluid, running; each ends within StreamClient's
  // bounds on a close (about 10 s), which the destructor may wait out.
  std::vector<std::future<void>> goodbyes_;
  std::optional<v1::Snapshot> snapshot_;
  std::shared_ptr<Standby> standby_;
  // The server went before the standby had started: it goes on here once started.
  struct StartingHere {
    std::shared_ptr<Standby> standby;
    std::string why;  // the server went
  };
  std::optional<StartingHere> starting_here_;
  std::future<Reconnected> reconnect_;
  Clock::time_point last_snapshot_{}, last_retry_{}, last_remote_frame_{};

  // Set by a handback's thread as it pauses the fluid here to put its state in the server's
  // session, until the handback ends: what the user sends meanwhile waits in held_back_ for the
  // side the fluid goes on from, a pointer's moves and the tilts each as the newest, at most
  // kMaxHeldBack (twice that for fingers lifted); timed from when they were held.
  struct Handback {
    std::mutex mutex;  // also held while a message goes out
    bool local_paused = false;
  };
  const std::shared_ptr<Handback> handback_ = std::make_shared<Handback>();
  struct HeldBack {
    v1::ClientMessage message;
    Clock::time_point held;
  };
  std::vector<HeldBack> held_back_;  // under handback_->mutex
  static constexpr std::size_t kMaxHeldBack = 1024;
  struct Point {
    float x, y;
  };
  std::map<std::uint32_t, Point> held_pointers_;  // down, as the user last sent them

  std::uint64_t show_from_event_ = 0;  // frames reflecting older events are from before a change
  bool awaiting_first_local_frame_ = false;
  bool report_next_frame_ = false;  // the first frame after handing back is said
  std::optional<double> handoff_gap_ms_;
};

}  // namespace fluidcast::client

#include "handoff_stream.h"

#include <cstdio>
#include <mutex>
#include <thread>
#include <utility>

namespace fluidcast::client {
namespace {

template <typename T>
bool ready(const std::future<T>& request) {
  return request.valid() && request.wait_for(std::chrono::seconds(0)) == std::future_status::ready;
}

// What a reconnection throws when the stream came back but did not take the fluid here: that
// stream, whose seat goes unused.
class FluidNotTaken : public std::runtime_error {
 public:
  FluidNotTaken(std::shared_ptr<FluidStream> unused, const std::string& why)
      : std::runtime_error(why), stream(std::move(unused)) {}
  std::shared_ptr<FluidStream> stream;
};

// The scene, solver and count of a session, for a new one that continues it elsewhere.
void continue_session(v1::Hello& hello, const v1::SessionState& state) {
  hello.mutable_create()->set_scene(state.scene());
  hello.mutable_create()->set_solver(state.solver());
  hello.mutable_create()->set_particles(state.particles());
}

// Pauses `fluid`, or sets it going; returns the event's id.
std::uint64_t set_paused(FluidStream& fluid, bool paused) {
  v1::Command pause;
  pause.set_pause(paused);
  return fluid.command(pause);
}

}  // namespace

// A local fluid kept warm while streaming (paused, one frame a second), so that a handoff needs no
// start-up (a Vulkan context, pipelines, the solver): it starts on a thread of its own, or is the
// fluid that just went back to the server; each snapshot goes in as it arrives, on the thread that
// fetched it.
class HandoffStream::Standby {
 public:
  Standby(const std::function<std::shared_ptr<FluidStream>(const v1::Hello&)>& start_local,
          v1::Hello hello)
      : start_(std::async(std::launch::async, [this, start_local, hello = std::move(hello)] {
          std::shared_ptr<FluidStream> local = start_local(hello);
          set_paused(*local, true);
          const std::lock_guard lock(mutex_);
          local_ = std::move(local);
        })) {}
  // A fluid here already paused (its state just went to the server).
  explicit Standby(std::shared_ptr<FluidStream> paused) : local_(std::move(paused)) {
    std::promise<void> started;
    started.set_value();
    start_ = started.get_future();
  }

  // Whether take() would not wait for the start (started, or failed to).
  bool started() const { return ready(start_); }

  // Any thread. A state that does not go in is said when a handoff loads it again.
  void put(const v1::Snapshot& snapshot) {
    const std::lock_guard lock(mutex_);
    holds_state_ = false;
    if (!local_) return;
    try {
      local_->load(snapshot);
      holds_state_ = true;
    } catch (const std::exception&) {
    }
  }

  bool holds_state() const {
    const std::lock_guard lock(mutex_);
    return holds_state_;
  }

  struct Taken {
    std::shared_ptr<FluidStream> fluid;
    bool holds_state = false;  // the newest snapshot is in it
  };
  // Once: waits for the start (throws why it failed) and for a snapshot going in.
  Taken take() {
    start_.get();
    const std::lock_guard lock(mutex_);
    return {std::exchange(local_, nullptr), holds_state_};
  }

 private:
  mutable std::mutex mutex_;  // held while a snapshot goes in, and while the fluid is taken
  std::shared_ptr<FluidStream> local_;  // null until started, and once taken
  bool holds_state_ = false;
  std::future<void> start_;  // last: waited for before the members it writes go
};

HandoffStream::HandoffStream(v1::Hello hello, HandoffSides sides, HandoffOptions options)
    : hello_(std::move(hello)), sides_(std::move(sides)), options_(std::move(options)) {
  open_first();
}

HandoffStream::~HandoffStream() { give_up_reconnecting(); }

void HandoffStream::open_first() {
  if (options_.local) {
    stream_ = sides_.start_local(hello_);
    set_status("local");
    return;
  }
  try {
    stream_ = sides_.connect(hello_, closing_.get_token());
  } catch (const Unreachable& e) {
    if (!options_.handoff || !options_.retry) throw;
    set_status(std::string("cannot connect: ") + e.what() + "; retrying");
    return;
  }
  remote_ = streamed_before_ = true;
  last_remote_frame_ = Clock::now();
  set_status("streaming from " + sides_.server);
}

const v1::Welcome& HandoffStream::welcome() const {
  static const v1::Welcome none;
  return stream_ ? stream_->welcome() : none;
}

std::uint64_t HandoffStream::send(v1::ClientMessage message) {
  if (message.has_command() && message.command().has_viewport()) {
    *hello_.mutable_viewport() = message.command().viewport();
  }
  if (message.has_command() && message.command().has_quality()) {
    *hello_.mutable_quality() = message.command().quality();
  }
  if (message.has_command() && message.command().kind_case() == v1::Command::kPause) {
    paused_ = message.command().pause();
  }
  // Held while it goes out, so that a handback cannot pause the fluid here in between.
  const std::lock_guard lock(handback_->mutex);
  if (handback_->local_paused) {  // for the session the fluid is going to, or back to it here
    hold_back(std::move(message));
    return 0;
  }
  const std::uint64_t id = deliver(std::move(message));
  if (id) latency_.sent(id);
  return id;
}

namespace {

// The latest event of a pointer or the latest tilt waiting in `held`, which a newer one of the
// same kind replaces: a drag or a turning phone held back for seconds takes one entry, not one a
// frame.
bool replaces(const v1::ClientMessage& waiting, const v1::ClientMessage& newer) {
  if (newer.has_tilt()) return waiting.has_tilt();
  return newer.has_pointer() && newer.pointer().phase() == v1::PointerEvent::MOVE &&
         waiting.has_pointer() && waiting.pointer().phase() == v1::PointerEvent::MOVE &&
         waiting.pointer().pointer_id() == newer.pointer().pointer_id();
}

}  // namespace

void HandoffStream::hold_back(v1::ClientMessage message) {
  for (auto it = held_back_.rbegin(); it != held_back_.rend(); ++it) {
    if (replaces(it->message, message)) {
      it->message = std::move(message);
      return;
    }
    // A finger's DOWN or UP since: its moves before it stay where they are.
    if (message.has_pointer() && it->message.has_pointer() &&
        it->message.pointer().pointer_id() == message.pointer().pointer_id()) {
      break;
    }
  }
  // Past the bound (a handback that hangs, taps that go on) the newest are dropped, but for a
  // finger's lifting: a finger left down would stir on.
  const bool lifts = message.has_pointer() && (message.pointer().phase() == v1::PointerEvent::UP ||
                                               message.pointer().phase() == v1::PointerEvent::CANCEL);
  if (held_back_.size() >= (lifts ? 2 : 1) * kMaxHeldBack) return;
  held_back_.push_back({std::move(message), Clock::now()});
}

std::uint64_t HandoffStream::deliver(v1::ClientMessage message) {
  const bool pause = message.has_command() && message.command().kind_case() == v1::Command::kPause;
  std::optional<v1::PointerEvent> pointer;
  if (message.has_pointer()) pointer = message.pointer();
  const std::uint64_t id = stream_ ? stream_->send(std::move(message)) : 0;
  if (pointer) track(*pointer, id != 0);
  if (pause && remote_ && id) pause_asked_ = id;
  return id;
}

void HandoffStream::track(const v1::PointerEvent& event, bool sent) {
  const auto phase = event.phase();
  if (phase == v1::PointerEvent::UP || phase == v1::PointerEvent::CANCEL) {
    held_pointers_.erase(event.pointer_id());
    return;
  }
  // Only what a side took: a DOWN pressed again must be one it takes again.
  const std::uint32_t ids = welcome().rules().pointer_ids();
  const bool valid = (phase == v1::PointerEvent::DOWN || phase == v1::PointerEvent::MOVE) &&
                     (ids == 0 || event.pointer_id() < ids) && event.x() >= 0.0f &&
                     event.x() <= 1.0f && event.y() >= 0.0f && event.y() <= 1.0f;
  // While the fluid here starts nothing takes a finger: one pressed meanwhile goes down there
  // once it has (press_held_pointers), where it was last.
  const bool kept_for_the_start = starting_here_ && (phase == v1::PointerEvent::DOWN ||
                                                     held_pointers_.contains(event.pointer_id()));
  if ((sent || kept_for_the_start) && valid) {
    held_pointers_[event.pointer_id()] = {event.x(), event.y()};
  }
}

void HandoffStream::press_held_pointers() {
  for (const auto& [id, at] : held_pointers_) {
    v1::ClientMessage down;
    down.mutable_pointer()->set_pointer_id(id);
    down.mutable_pointer()->set_phase(v1::PointerEvent::DOWN);
    down.mutable_pointer()->set_x(at.x);
    down.mutable_pointer()->set_y(at.y);
    try {
      stream_->send(std::move(down));
    } catch (const std::exception& e) {  // a side that refuses it: the finger is not held there
      say(std::string("a finger held down did not go down here: ") + e.what());
    }
  }
}

void HandoffStream::release_held_back() {
  std::vector<HeldBack> held;
  {
    const std::lock_guard lock(handback_->mutex);
    handback_->local_paused = false;
    held.swap(held_back_);
  }
  for (HeldBack& waiting : held) {
    try {
      if (const std::uint64_t id = deliver(std::move(waiting.message))) {
        latency_.sent(id, waiting.held);
      }
    } catch (const std::exception& e) {  // refused by the side it went to, as if sent there
      say(std::string("held back and then refused: ") + e.what());
    }
  }
}

std::optional<v1::Frame> HandoffStream::next_frame(std::chrono::milliseconds timeout) {
  std::optional<v1::Frame> frame;
  if (stream_ && !server_ended_) {
    frame = stream_->next_frame(timeout);
    if (frame && remote_ && frame->input_event_id() >= pause_asked_) pause_asked_ = 0;
    if (frame && frame->input_event_id() < show_from_event_) frame.reset();
    if (frame) {
      latency_.frame_reflects(frame->input_event_id());
      shown(*frame);
    }
    // While streaming, the session's pause, whichever viewer set it, is this viewer's (once the
    // session showed this viewer's own last ask): a fluid continued here goes on as the session
    // last showed it.
    if (remote_ && pause_asked_ == 0) paused_ = welcome().state().paused();
    keep_snapshot();
    keep_standby();
    if (remote_ && stream_->ended()) {
      stream_->lost() ? lost(stream_->end_reason()) : ended_by_server();
    } else if (remote_ && Clock::now() - last_remote_frame_ > options_.stall_after) {
      lost("nothing came for " + std::to_string(options_.stall_after.count()) + " ms");
    }
  } else {
    std::this_thread::sleep_for(timeout);
    continue_when_started();
  }
  // The server is asked again once the fluid here goes on: its state is what goes back.
  if (!options_.local && !remote_ && !starting_here_ && options_.retry) reconnect();
  return frame;
}

bool HandoffStream::ended() const {
  return server_ended_ ||
         (options_.local ? stream_->ended() : !stream_ && !starting_here_ && !options_.retry);
}

std::string HandoffStream::end_reason() const {
  return stream_ ? stream_->end_reason() : ended() ? status_ : "";
}

std::string HandoffStream::close() {
  give_up_reconnecting();
  return stream_ ? stream_->close() : status_;
}

void HandoffStream::give_up_reconnecting() {
  closing_.request_stop();
  if (!reconnect_.valid()) return;
  try {
    reconnect_.get().stream->close();
  } catch (const FluidNotTaken& e) {
    e.stream->close();
  } catch (const std::exception&) {  // it opened none
  }
}

FluidStream& HandoffStream::current() const {
  if (!stream_) throw std::runtime_error("no fluid: the server is gone and none continues here");
  return *stream_;
}

v1::Snapshot HandoffStream::snapshot() { return current().snapshot(); }

void HandoffStream::load(const v1::Snapshot& snapshot) { current().load(snapshot); }

bool HandoffStream::continues_here() const {
  return options_.handoff && welcome().access().control() &&
         welcome().state().particles() <= options_.max_local_particles;
}

void HandoffStream::shown(const v1::Frame& frame) {
  const auto now = Clock::now();
  if (report_next_frame_) {
    report_next_frame_ = false;
    char line[96];
    std::snprintf(line, sizeof line, "first frame streamed after the handoff: t = %.3f s",
                  frame.sim_time());
    say(line);
  }
  if (awaiting_first_local_frame_) {
    awaiting_first_local_frame_ = false;
    handoff_gap_ms_ = std::chrono::duration<double, std::milli>(now - last_remote_frame_).count();
    say("handoff gap " + std::to_string(int(*handoff_gap_ms_)) + " ms");
  }
  if (remote_) last_remote_frame_ = now;
}

void HandoffStream::keep_snapshot() {
  std::erase_if(abandoned_,
                [](const std::future<v1::Snapshot>& request) { return ready(request); });
  if (!remote_ || !continues_here()) return;
  if (ready(snapshot_request_)) {
    try {
      snapshot_ = snapshot_request_.get();
    } catch (const std::exception&) {  // the server may be going: the one we have will do
    }
  }
  const auto now = Clock::now();
  if (snapshot_request_.valid() || now - last_snapshot_ < options_.snapshot_every) return;
  last_snapshot_ = now;
  // The request holds the stream, which may be let go of here before it ends. The standby it
  // holds weakly: a request's task lives as long as its future, which a stream the server ended
  // keeps, and the warm fluid would live on with it.
  snapshot_request_ =
      std::async(std::launch::async, [remote = stream_, standby = std::weak_ptr(standby_)] {
        v1::Snapshot snapshot = remote->snapshot();
        if (const std::shared_ptr<Standby> held = standby.lock()) held->put(snapshot);
        return snapshot;
      });
}

void HandoffStream::keep_standby() {
  if (!remote_ || standby_ || !continues_here()) return;
  v1::Hello hello = hello_;
  continue_session(hello, welcome().state());
  hello.mutable_quality()->set_max_fps(1);
  standby_ = std::make_shared<Standby>(sides_.start_local, std::move(hello));
}

// The server ended the stream on purpose (bad input, an idle session): that stands; nothing
// carries the fluid on or asks again.
void HandoffStream::ended_by_server() {
  server_ended_ = true;
  standby_.reset();
  set_status("the server ended the stream: " + stream_->end_reason());
}

void HandoffStream::lost(const std::string& why) {
  // A request still on its way to a dying server is not waited for: the last state will do.
  if (snapshot_request_.valid()) abandoned_.push_back(std::move(snapshot_request_));
  const std::uint32_t particles = welcome().state().particles();
  const bool may_continue = continues_here();
  const v1::Access& access = welcome().access();
  resume_.reset();
  if (!access.resume_key().empty()) {
    resume_.emplace();
    resume_->set_key(access.resume_key());
    resume_->set_session_key(access.control() ? access.control_key() : access.view_key());
  }
  stream_.reset();
  remote_ = false;
  std::shared_ptr<Standby> standby = std::exchange(standby_, nullptr);
  // A state the standby took on the side counts even before this thread collected it.
  if (may_continue && standby && (snapshot_ || standby->holds_state())) {
    // Its start, if still under way (a server that went within seconds of streaming), is waited
    // for by next_frame's calls, not in one: a window goes on answering meanwhile.
    starting_here_ = {std::move(standby), why};
    if (!continue_when_started()) {
      set_status("the server is gone (" + why + "): starting the fluid here");
    }
    return;
  }
  const bool too_big = options_.handoff && particles > options_.max_local_particles;
  set_status("the server is gone (" + why + "); " +
             (too_big ? "this session is too big to continue here (" + std::to_string(particles) +
                            " particles); "
                      : std::string()) +
             (options_.retry ? "retrying" : "not asking again"));
}

bool HandoffStream::continue_when_started() {
  if (!starting_here_ || !starting_here_->standby->started()) return false;
  const StartingHere starting = *std::exchange(starting_here_, std::nullopt);
  continue_here(*starting.standby, starting.why);
  return true;
}

void HandoffStream::continue_here(Standby& standby, const std::string& why) {
  Standby::Taken local;
  try {
    local = standby.take();
  } catch (const std::exception& e) {
    set_status(std::string("the server is gone and the local fluid cannot start: ") + e.what());
    return;
  }
  try {
    if (!local.holds_state) local.fluid->load(snapshot_.value());  // throws if there is none
  } catch (const std::exception& e) {
    set_status(std::string("the server is gone and its state does not fit here: ") + e.what());
    return;
  }
  try {  // as this viewer last asked: its quality, its size, paused or not
    v1::Command wake;
    *wake.mutable_quality() = hello_.quality();
    local.fluid->command(wake);
    *wake.mutable_viewport() = hello_.viewport();
    local.fluid->command(wake);
    wake.set_pause(paused_);
    show_from_event_ = local.fluid->command(wake);
  } catch (const std::exception& e) {
    set_status(std::string("the server is gone and the local fluid refused to go on: ") + e.what());
    return;
  }
  stream_ = std::move(local.fluid);
  press_held_pointers();  // a finger held down as the server went stirs the fluid here
  latency_.forget_unanswered();
  awaiting_first_local_frame_ = true;
  set_status("the server is gone (" + why + "): continuing locally" +
             (options_.retry ? ", retrying" : ""));
}

void HandoffStream::reconnect() {
  if (reconnect_.valid()) {
    if (!ready(reconnect_)) return;
    try {
      came_back(reconnect_.get());
    } catch (const Unreachable&) {  // still gone
    } catch (const Forgotten& e) {  // the next attempt, at once, asks for a new session
      resume_.reset();
      last_retry_ = {};
      set_status(std::string("the server is back but no longer has the session (") + e.what() +
                 "); asking for a new one");
    } catch (const std::exception& e) {
      // The fluid here, paused while its state went over, goes on as the user last asked, with
      // what they did meanwhile. It goes into a new session next: a resume the server refused
      // may be refused again (the fluid here needs no old seat), and one that did not take the
      // fluid spent its key.
      if (stream_) {
        set_paused(*stream_, paused_);
        resume_.reset();
      }
      // A stream that did not take the fluid says goodbye, so that the server keeps its seat for
      // no resume (a session nobody else watches ends at once, its slot free for the next try);
      // off this thread and after the fluid here went on, as a server may take seconds to answer.
      if (const auto* not_taken = dynamic_cast<const FluidNotTaken*>(&e)) {
        std::erase_if(goodbyes_, [](const std::future<void>& goodbye) { return ready(goodbye); });
        goodbyes_.push_back(
            std::async(std::launch::async, [stream = not_taken->stream]() mutable {
              stream->close();
              stream.reset();  // its channel goes now, not when the future is collected
            }));
      }
      set_status(std::string("the server is back but refused a session: ") + e.what() +
                 (stream_ ? "; continuing locally, retrying" : "; retrying"));
    }
    release_held_back();
    return;
  }
  const auto now = Clock::now();
  if (now - last_retry_ < options_.retry_every) return;
  last_retry_ = now;
  // The session left is asked for first, the fluid here going into it: whoever else watches it
  // sees it go on, and it frees no seat later (its key takes a new one where this viewer's seat
  // was forgotten). Once the server no longer has it, a new one.
  v1::Hello hello = hello_;
  if (resume_) {
    *hello.mutable_resume() = *resume_;
  } else if (stream_) {
    continue_session(hello, welcome().state());
  }
  reconnect_ = std::async(std::launch::async, [connect = sides_.connect, hello, local = stream_,
                                                handback = handback_,
                                                closing = closing_.get_token()] {
    Reconnected back{connect(hello, closing), {}, hello.has_resume()};
    if (!local || closing.stop_requested()) return back;  // closing: no fluid goes over
    // The fluid here stops while its state goes over, and what its user does meanwhile is held
    // back for where it goes on (refused, here: reconnect() unpauses it as its user last asked).
    try {
      {
        const std::lock_guard lock(handback->mutex);
        handback->local_paused = true;
        set_paused(*local, true);
      }
      v1::Snapshot state = local->snapshot();
      back.stream->load(state);
      back.state_put = std::move(state);
    } catch (const std::exception& e) {  // the fluid stays here: the stream goes unused
      throw FluidNotTaken(std::move(back.stream),
                          std::string("it did not take the fluid here (") + e.what() + ")");
    }
    return back;
  });
}

void HandoffStream::came_back(Reconnected back) {
  show_from_event_ = 0;
  pause_asked_ = 0;  // another stream's event ids
  if (const auto& state = back.state_put) {
    char line[160];
    std::snprintf(line, sizeof line,
                  "the server is back and took the state (%d particles, t = %.3f s) into %s",
                  state->positions_size() / 3, state->time(),
                  back.resumed ? "the session it left" : "a new session");
    say(line);
    try {
      // As the fluid here was: a new session runs, and the one left may be paused.
      if (paused_ || back.resumed) pause_asked_ = set_paused(*back.stream, paused_);
      v1::Command marker;  // frames from before the state went in reflect no later event
      *marker.mutable_quality() = hello_.quality();
      show_from_event_ = back.stream->command(marker);
      report_next_frame_ = true;
    } catch (const std::exception& e) {
      say(e.what());
    }
  }
  // The fluid here, paused as its state went over, waits warm for the next handoff.
  if (std::shared_ptr<FluidStream> here = std::exchange(stream_, std::move(back.stream))) {
    try {
      // The fingers held down go down on the server's side (below), and lift here: a finger left
      // down in the standby would stir the next handoff's fluid where it pressed long before.
      for (const auto& [id, at] : held_pointers_) {
        v1::ClientMessage lift;
        lift.mutable_pointer()->set_pointer_id(id);
        lift.mutable_pointer()->set_phase(v1::PointerEvent::CANCEL);
        lift.mutable_pointer()->set_x(at.x);
        lift.mutable_pointer()->set_y(at.y);
        here->send(std::move(lift));
      }
      v1::Command slow;  // as a standby started for it draws
      *slow.mutable_quality() = hello_.quality();
      slow.mutable_quality()->set_max_fps(1);
      here->command(slow);
      standby_ = std::make_shared<Standby>(std::move(here));
    } catch (const std::exception& e) {  // a new one starts instead (keep_standby)
      say(std::string("the fluid here cannot wait for the next handoff: ") + e.what());
    }
  }
  latency_.forget_unanswered();
  remote_ = true;
  press_held_pointers();  // the new or resumed session has not seen them go down
  release_held_back();
  resume_.reset();
  last_remote_frame_ = Clock::now();
  snapshot_.reset();
  set_status("streaming from " + sides_.server + (streamed_before_ ? " again" : ""));
  streamed_before_ = true;
}

void HandoffStream::set_status(std::string status) {
  status_ = std::move(status);
  say(status_);
}

void HandoffStream::say(const std::string& line) const {
  if (options_.say) options_.say(line);
}

}  // namespace fluidcast::client

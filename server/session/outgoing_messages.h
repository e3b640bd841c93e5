// What a transport has yet to write to one viewer, behind its one write in flight: control
// messages (Welcome, StreamEnd) in order and never dropped, at most one session state and one
// state (a newer one of each replaces the waiting one; a session state, telling of a change, drops
// the state from before it), and at most one frame — a newer frame replaces the waiting one, and
// a frame no newer than one already queued (encoders finish in any order) is dropped. Memory per
// viewer stays bounded however slowly the client reads. Not thread-safe: each transport calls it
// under its own lock or strand.
#pragma once

#include <chrono>
#include <cstdint>
#include <deque>
#include <memory>
#include <optional>

#include "fluidcast/v1/fluidcast.pb.h"

namespace fluidcast::server {

class OutgoingMessages {
 public:
  // False when a frame was dropped: this one (stale, or frames are stopped) or the one it
  // replaced.
  bool push(std::shared_ptr<const v1::ServerMessage> message);
  // The next message to write, control messages first; null when there is none.
  std::shared_ptr<const v1::ServerMessage> next();
  // The stream is ending: the waiting frame, states and later ones are dropped; control
  // messages still go.
  void stop_frames();
  // The message next() gave has been written: when it was a frame, the milliseconds from its
  // push to now (waiting behind the write before it, then being written): its send time.
  std::optional<double> written();

 private:
  using Clock = std::chrono::steady_clock;
  std::deque<std::shared_ptr<const v1::ServerMessage>> control_;
  std::shared_ptr<const v1::ServerMessage> session_;  // ServerMessage.session
  std::shared_ptr<const v1::ServerMessage> state_;
  std::shared_ptr<const v1::ServerMessage> frame_;
  Clock::time_point frame_pushed_{};
  std::optional<Clock::time_point> writing_frame_pushed_;
  std::uint64_t newest_sequence_ = 0;
  bool frames_stopped_ = false;
};

}  // namespace fluidcast::server

// A fluid to watch and touch, wherever it runs: a server's session over gRPC (StreamClient), a
// session simulated and rendered in this process (LocalStream), or one that moves between the two
// (HandoffStream).
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "fluidcast/v1/fluidcast.pb.h"

namespace fluidcast::client {

// Touch-to-photon: from sending input event N to the first frame that reflects it. Thread-safe.
class LatencyTracker {
 public:
  std::uint64_t sent();         // a new event id, timed from now
  // An event whose id another stream gave it, timed from now, or from when it was held back.
  void sent(std::uint64_t id,
            std::chrono::steady_clock::time_point at = std::chrono::steady_clock::now());
  void frame_reflects(std::uint64_t newest_event);
  // Events not answered yet are forgotten: their ids belonged to a stream that is gone.
  void forget_unanswered();
  std::vector<double> latencies_ms() const;

 private:
  mutable std::mutex mutex_;
  std::uint64_t next_ = 1;
  std::map<std::uint64_t, std::chrono::steady_clock::time_point> unanswered_;
  std::vector<double> latencies_ms_;
};

// The value below which a share `p` (0 to 1) of `values` lies; 0 for none.
double percentile(std::vector<double> values, double p);

// Frames received and not yet shown: the newest `keep`, waited for with a timeout. Thread-safe.
class FrameQueue {
 public:
  explicit FrameQueue(std::size_t keep) : keep_(keep) {}
  void push(v1::Frame frame);
  void close();  // no more frames will come: waiters return at once
  std::optional<v1::Frame> pop(std::chrono::milliseconds timeout);
  bool closed() const;
  bool wait_closed(std::chrono::milliseconds timeout);  // true once closed

 private:
  const std::size_t keep_;
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<v1::Frame> frames_;
  bool closed_ = false;
};

// The session's newest state as its other side tells it (ServerMessage.session): set on the
// thread that receives it, taken into the Welcome by the thread that uses the stream. Thread-safe.
class SessionChanges {
 public:
  void arrived(v1::SessionState state);
  // Puts the newest state that arrived since the last call, if any, into `welcome`.
  void apply_to(v1::Welcome& welcome);

 private:
  std::mutex mutex_;
  std::optional<v1::SessionState> newest_;
};

class FluidStream {
 public:
  virtual ~FluidStream() = default;
  // Its state renewed as the session changes (another scene or count, a pause, by any viewer), on
  // the thread that calls next_frame, as that returns.
  virtual const v1::Welcome& welcome() const = 0;
  // Input; each returns the event id it was sent with (0 when the stream has ended, or for an
  // event a HandoffStream holds back to send later).
  virtual std::uint64_t send(v1::ClientMessage message) = 0;
  std::uint64_t pointer(std::uint32_t id, v1::PointerEvent::Phase phase, float x, float y);
  std::uint64_t tilt(float x, float y, float z);
  std::uint64_t command(const v1::Command& command);
  // The next frame (acknowledged); nothing when none came within `timeout` or the stream ended.
  virtual std::optional<v1::Frame> next_frame(std::chrono::milliseconds timeout) = 0;
  virtual bool ended() const = 0;
  virtual std::string end_reason() const = 0;
  // Whether it ended because the other side went away (a server stopping, a network gone), not
  // because it ended the stream on purpose (bad input, an idle session): only a loss is worth
  // carrying on elsewhere and asking again.
  virtual bool lost() const = 0;
  // Ends the stream in order: what was sent is written, then the other side's goodbye awaited (a
  // few seconds at most). Says how it ended: empty when well, else why.
  virtual std::string close() = 0;
  // The fluid's state now, and a state simulated elsewhere put in: what a handoff moves. Either
  // may run on another thread than the one reading frames; both throw what the session refused.
  virtual v1::Snapshot snapshot() = 0;
  virtual void load(const v1::Snapshot& snapshot) = 0;
  // Touch-to-photon latencies measured so far, ms.
  std::vector<double> latencies_ms() const { return latency_.latencies_ms(); }

 protected:
  LatencyTracker latency_;
};

}  // namespace fluidcast::client

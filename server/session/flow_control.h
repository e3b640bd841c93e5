// How often one viewer gets a frame and what each costs it: the frame rate it asked for, the
// frames it has not acknowledged (a viewer that falls behind, or never acknowledges, is
// throttled), the round trip its acknowledgements measure, and adaptive quality — JPEG quality
// first, then the frame size, lowered while it falls behind and raised while it keeps up. Pure
// arithmetic on the times it is given: the Viewer applies what it decides.
#pragma once

#include <array>
#include <chrono>
#include <cstdint>
#include <optional>

namespace fluidcast::server {

using Clock = std::chrono::steady_clock;

class FlowControl {
 public:
  // Frames sent and not yet acknowledged, beyond which a viewer is throttled: the newest frame
  // wins, and a slow viewer gets fewer. One that never acknowledges is throttled from its fourth
  // frame on.
  static constexpr std::uint64_t kMaxFramesInFlight = 3;
  // A throttled viewer still gets a frame this often: one that does not acknowledge (a client
  // written without FrameAck) sees the fluid slowly rather than not at all.
  static constexpr auto kThrottledFrameEvery = std::chrono::seconds(1);
  // At most one adaptation this often.
  static constexpr auto kAdaptEvery = std::chrono::milliseconds(250);
  static constexpr int kDefaultQuality = 80;
  static constexpr int kLowestAdaptiveQuality = 35;
  static constexpr std::uint32_t kSmallestAdaptiveHeight = 120;
  // Round trips above which a viewer is behind, and below which it keeps up.
  static constexpr double kBehindMs = 120.0, kKeepingUpMs = 50.0;

  // A viewer's, from `start` (when it joined).
  explicit FlowControl(Clock::time_point start) : last_rendered_(start) {}

  struct Size {
    std::uint32_t width = 0, height = 0;
    bool operator==(const Size&) const = default;
  };

  // What the viewer asked for: frames a second, JPEG quality (0: the default), adaptation. A new
  // rate starts now, and the frame size goes back to the one asked.
  void ask(std::uint32_t fps, std::uint32_t jpeg_quality, bool adaptive);
  // The frame size asked for; adaptation starts from it again.
  void ask_size(Size size);

  // Whether a frame is due now: its rate, and not too many in flight (or, throttled, one has not
  // been sent for kThrottledFrameEvery).
  bool due(Clock::time_point now) const;
  bool throttled() const { return sequence_ - acknowledged_ >= kMaxFramesInFlight; }
  // Whether throttling holds back a frame its rate has due now: true once a frame interval at
  // most, so that a count of them counts frames, not the server's ticks.
  bool skips_frame(Clock::time_point now);
  // How long ago its next frame fell due (negative before).
  Clock::duration overdue(Clock::time_point now) const { return now - next_frame_; }
  // How long since its last frame was rendered (since `start` before its first): what the
  // session's frame rate floors go by, which a new rate (ask) does not reset.
  Clock::duration since_rendered(Clock::time_point now) const { return now - last_rendered_; }
  // A frame was rendered now: the next one is due an interval later.
  void rendered(Clock::time_point now);
  // A rendered frame is handed to the viewer now; returns its sequence number.
  std::uint64_t produced(Clock::time_point now);
  // The viewer acknowledged frame `sequence` (numbers it was not sent are ignored): the round
  // trip, and adaptation.
  void acknowledge(std::uint64_t sequence, Clock::time_point now);

  int jpeg_quality() const { return jpeg_quality_; }
  // The size to render at: the one asked, or smaller while adaptation lowers it.
  Size render_size() const { return render_size_; }
  std::optional<double> round_trip_ms() const { return round_trip_ms_; }

 private:
  void adapt(Clock::time_point now);

  Clock::duration frame_interval_{};
  Clock::time_point next_frame_{};
  Clock::time_point last_rendered_{};
  Clock::time_point next_skipped_{};  // when the next frame held back falls due
  std::uint64_t sequence_ = 0, acknowledged_ = 0;
  std::array<Clock::time_point, 64> produced_at_{};
  std::optional<double> round_trip_ms_;
  bool adaptive_ = false;
  int requested_quality_ = kDefaultQuality, jpeg_quality_ = kDefaultQuality;
  Size asked_size_, render_size_;
  Clock::time_point last_adapted_{};
};

}  // namespace fluidcast::server

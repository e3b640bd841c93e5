// Raw pointer events become gestures: one finger drags the fluid (or, for a viewer that may not
// touch it, orbits the camera), two fingers orbit (moving together) and zoom (pinching) the
// camera. Positions are normalised to the frame.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <map>
#include <optional>

#include "fluidcast/v1/fluidcast.pb.h"

namespace fluidcast::server {

struct GestureChange {
  bool drag_started = false;  // a single finger went down: grab the surface under it
  // The drag ended (its finger lifted, or a second finger joined): where its finger was last (an
  // UP's own point; a cancel's carries nothing the hand did, so the last move's), for the stretch
  // since the last tick to be followed.
  std::optional<glm::vec2> drag_ended_at;
  float yaw_degrees = 0.0f;  // two fingers: add to the camera's yaw and pitch
  float pitch_degrees = 0.0f;
  float zoom = 1.0f;  // two fingers: multiply the camera's distance
};

class Gestures {
 public:
  // Degrees of orbit for two fingers moving across the whole frame.
  static constexpr float kOrbitDegreesPerFrame = 180.0f;

  explicit Gestures(bool touches_fluid) : touches_fluid_(touches_fluid) {}

  GestureChange apply(const v1::PointerEvent& event);
  // Where the dragging finger is: nothing when no single finger drags.
  std::optional<glm::vec2> drag() const;

 private:
  bool dragging() const { return touches_fluid_ && pointers_.size() == 1 && !multi_touch_; }

  bool touches_fluid_;
  std::map<std::uint32_t, glm::vec2> pointers_;
  // Set once a second finger joined; the finger left behind does not drag until all are up.
  bool multi_touch_ = false;
};

}  // namespace fluidcast::server

// The orbit camera: looks at `target` from `distance` metres, turned by yaw about the vertical
// and raised by pitch. Matrices follow Vulkan's conventions (y down in clip space, depth 0 to 1).
#pragma once

#include <glm/glm.hpp>

#include "fluidcast/sim/particles.h"

namespace fluidcast::render {

struct OrbitCamera {
  // The ranges of every camera, whoever sets it: validate() and the server's validation of
  // Camera messages read these.
  static constexpr float kMaxPitchDegrees = 89.0f;
  static constexpr float kMaxDistance = 1000.0f;                            // m
  static constexpr float kMinFieldOfView = 1.0f, kMaxFieldOfView = 170.0f;  // degrees

  float yaw_degrees = 30.0f;            // about +y, from looking along −z
  float pitch_degrees = 20.0f;          // above the horizon, within ±kMaxPitchDegrees
  float distance = 2.5f;                // m, above 0, at most kMaxDistance
  glm::vec3 target{0.8f, 0.2f, 0.15f};  // m
  float field_of_view_degrees = 45.0f;  // vertical, kMinFieldOfView to kMaxFieldOfView

  // Throws std::invalid_argument naming the first value that is not finite or out of range.
  void validate() const;
  glm::vec3 eye() const;
  glm::mat4 view() const;
  glm::mat4 projection(float aspect) const;

  // Looks at the middle of `tank` from just far enough that all of it shows, with a margin, in a
  // frame of `aspect` (width / height; a portrait phone's too), at the present yaw, pitch and
  // field of view; never nearer or farther than orbit_limits(tank) allow.
  void fit(const sim::Box& tank, float aspect);
};

// The point in the scene at `depth` metres along the view axis under `screen`, a point of the frame
// (0 to 1 from its left and its top, as PointerEvent gives it), for a camera's `view` and
// `projection` matrices.
glm::vec3 unproject(const glm::mat4& view, const glm::mat4& projection, glm::vec2 screen,
                    float depth);

// Where gestures may take an orbit camera around a tank: outside it (beyond its bounding
// sphere), not so far that it shrinks to a speck, and not below its middle.
struct OrbitLimits {
  float min_distance, max_distance;  // m
  float min_pitch_degrees = 0.0f, max_pitch_degrees = OrbitCamera::kMaxPitchDegrees;

  void clamp(OrbitCamera& camera) const;
};
OrbitLimits orbit_limits(const sim::Box& tank);

}  // namespace fluidcast::render

// The orbit camera: looks at `target` from `distance` metres, turned by yaw about the vertical
// and raised by pitch. Matrices follow Vulkan's conventions (y down in clip space, depth 0 to 1).
#pragma once

#include <glm/glm.hpp>

namespace fluidcast::render {

struct OrbitCamera {
  float yaw_degrees = 30.0f;            // about +y, from looking along −z
  float pitch_degrees = 20.0f;          // above the horizon, −89 to 89
  float distance = 2.5f;                // m, positive
  glm::vec3 target{0.8f, 0.2f, 0.15f};  // m
  float field_of_view_degrees = 45.0f;  // vertical, 1 to 170

  // Throws std::invalid_argument naming the first value that is not finite or out of range.
  void validate() const;
  glm::vec3 eye() const;
  glm::mat4 view() const;
  glm::mat4 projection(float aspect) const;
};

}  // namespace fluidcast::render

#include "fluidcast/render/camera.h"

#include <algorithm>
#include <cmath>
#include <glm/gtc/matrix_transform.hpp>
#include <stdexcept>
#include <string>

namespace fluidcast::render {
namespace {

void require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument("camera: " + what);
}

}  // namespace

void OrbitCamera::validate() const {
  require(std::isfinite(yaw_degrees), "yaw must be finite");
  require(std::isfinite(pitch_degrees) && std::abs(pitch_degrees) <= kMaxPitchDegrees,
          "pitch must be between -89 and 89 degrees, got " + std::to_string(pitch_degrees));
  require(std::isfinite(distance) && distance > 0.0f && distance <= kMaxDistance,
          "distance must be above 0 and at most 1000 m, got " + std::to_string(distance));
  require(std::isfinite(target.x) && std::isfinite(target.y) && std::isfinite(target.z),
          "target must be finite");
  require(std::isfinite(field_of_view_degrees) && field_of_view_degrees >= kMinFieldOfView &&
              field_of_view_degrees <= kMaxFieldOfView,
          "field of view must be between 1 and 170 degrees, got " +
              std::to_string(field_of_view_degrees));
}

glm::vec3 OrbitCamera::eye() const {
  const float yaw = glm::radians(yaw_degrees), pitch = glm::radians(pitch_degrees);
  const glm::vec3 back(std::sin(yaw) * std::cos(pitch), std::sin(pitch),
                       std::cos(yaw) * std::cos(pitch));
  return target + distance * back;
}

glm::mat4 OrbitCamera::view() const { return glm::lookAtRH(eye(), target, glm::vec3(0, 1, 0)); }

glm::mat4 OrbitCamera::projection(float aspect) const {
  // Near and far around the target, so depth precision is spent where the fluid is.
  const float near = std::max(0.01f, 0.05f * distance), far = 20.0f * distance + 10.0f;
  glm::mat4 p = glm::perspectiveRH_ZO(glm::radians(field_of_view_degrees), aspect, near, far);
  p[1][1] *= -1.0f;  // Vulkan's clip space has y down
  return p;
}

glm::vec3 unproject(const glm::mat4& view, const glm::mat4& projection, glm::vec2 screen,
                    float depth) {
  const glm::vec2 ndc = 2.0f * screen - 1.0f;  // y down, as Vulkan's clip space
  const glm::vec4 in_view(ndc.x * depth / projection[0][0], ndc.y * depth / projection[1][1],
                          -depth, 1.0f);
  return glm::vec3(glm::inverse(view) * in_view);
}

void OrbitCamera::fit(const sim::Box& tank, float aspect) {
  constexpr float kMargin = 1.08f;
  target = 0.5f * (tank.min + tank.max);
  const float tan_y = std::tan(0.5f * glm::radians(field_of_view_degrees)), tan_x = tan_y * aspect;
  // The view's axes; each corner at depth distance − z must satisfy |x| ≤ depth · tan_x and
  // |y| ≤ depth · tan_y.
  distance = 1.0f;
  const glm::mat3 rotation(view());
  float needed = 0.0f;
  for (int corner = 0; corner < 8; ++corner) {
    const glm::vec3 p((corner & 1) ? tank.max.x : tank.min.x,
                      (corner & 2) ? tank.max.y : tank.min.y,
                      (corner & 4) ? tank.max.z : tank.min.z);
    const glm::vec3 c = rotation * (p - target);  // z towards the eye
    needed = std::max(
        {needed, c.z + std::abs(c.x) * kMargin / tan_x, c.z + std::abs(c.y) * kMargin / tan_y});
  }
  // A frame a few pixels wide would need the camera kilometres back: it stays within the orbit's
  // reach and shows what fits.
  const OrbitLimits limits = orbit_limits(tank);
  distance = std::clamp(needed, limits.min_distance, limits.max_distance);
}

OrbitLimits orbit_limits(const sim::Box& tank) {
  const float radius = 0.5f * glm::length(tank.size());
  return {1.05f * radius, std::min(16.0f * radius, OrbitCamera::kMaxDistance)};
}

void OrbitLimits::clamp(OrbitCamera& camera) const {
  camera.distance = std::clamp(camera.distance, min_distance, max_distance);
  camera.pitch_degrees = std::clamp(camera.pitch_degrees, min_pitch_degrees, max_pitch_degrees);
}

}  // namespace fluidcast::render

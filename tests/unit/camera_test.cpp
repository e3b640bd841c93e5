// The orbit camera's fit and limits, without a GPU: the whole tank in the frame on a portrait
// phone, a landscape screen and a square, snugly; gestures kept outside the tank and above its
// middle.
#include "fluidcast/render/camera.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace fluidcast::render {
namespace {

const sim::Box kTank{{0, 0, 0}, {1.6f, 1.0f, 0.3f}};  // the dam break's

// The largest |x| and |y| of the tank's corners in normalised device coordinates.
glm::vec2 extent_in_frame(const OrbitCamera& camera, float aspect) {
  const glm::mat4 clip = camera.projection(aspect) * camera.view();
  glm::vec2 extent(0.0f);
  for (int corner = 0; corner < 8; ++corner) {
    const glm::vec3 p((corner & 1) ? kTank.max.x : kTank.min.x,
                      (corner & 2) ? kTank.max.y : kTank.min.y,
                      (corner & 4) ? kTank.max.z : kTank.min.z);
    const glm::vec4 c = clip * glm::vec4(p, 1.0f);
    EXPECT_GT(c.w, 0.0f) << "a corner behind the camera";
    extent = glm::max(extent, glm::abs(glm::vec2(c) / c.w));
  }
  return extent;
}

TEST(OrbitCamera, FitShowsTheWholeTankInAnyFrameShape) {
  for (float aspect : {390.0f / 844.0f, 16.0f / 9.0f, 1.0f, 3.0f}) {
    for (float yaw : {0.0f, 30.0f, 90.0f, 200.0f}) {
      OrbitCamera camera;
      camera.yaw_degrees = yaw;
      camera.fit(kTank, aspect);
      const glm::vec2 extent = extent_in_frame(camera, aspect);
      EXPECT_LE(std::max(extent.x, extent.y), 1.0f) << "aspect " << aspect << ", yaw " << yaw;
      EXPECT_GT(std::max(extent.x, extent.y), 0.85f) << "not snug: aspect " << aspect;
      EXPECT_EQ(camera.target, 0.5f * (kTank.min + kTank.max));
    }
  }
  // A portrait phone needs the camera farther back than a landscape screen.
  OrbitCamera portrait, landscape;
  portrait.fit(kTank, 390.0f / 844.0f);
  landscape.fit(kTank, 16.0f / 9.0f);
  EXPECT_GT(portrait.distance, 1.5f * landscape.distance);
}

// A client may ask for any frame from 1 pixel up to the server's limits: a sliver 1 pixel wide and
// 2160 tall would need the camera 5 km back to show the whole tank; it stops at the orbit's reach,
// a camera the renderer accepts.
TEST(OrbitCamera, FitStaysWithinTheOrbitsReachForASliverOfAFrame) {
  const OrbitLimits limits = orbit_limits(kTank);
  for (float aspect : {1.0f / 2160.0f, 2160.0f}) {
    OrbitCamera camera;
    camera.fit(kTank, aspect);
    EXPECT_LE(camera.distance, limits.max_distance) << "aspect " << aspect;
    EXPECT_GE(camera.distance, limits.min_distance) << "aspect " << aspect;
    EXPECT_NO_THROW(camera.validate()) << "aspect " << aspect;
  }
}

TEST(OrbitCamera, LimitsKeepTheCameraOutsideTheTankAndAboveItsMiddle) {
  const OrbitLimits limits = orbit_limits(kTank);
  OrbitCamera camera;
  camera.fit(kTank, 1.0f);
  camera.distance = 0.01f;  // pinched all the way in
  camera.pitch_degrees = -60.0f;
  limits.clamp(camera);
  EXPECT_GT(glm::length(camera.eye() - camera.target), 0.5f * glm::length(kTank.size()));
  EXPECT_FALSE(kTank.contains(camera.eye()));
  EXPECT_GE(camera.pitch_degrees, 0.0f);
  camera.distance = 1e4f;
  limits.clamp(camera);
  EXPECT_LE(camera.distance, limits.max_distance);
  EXPECT_GE(camera.distance, limits.min_distance);
}

// One set of ranges: what validate() refuses is what the server's Camera validation refuses.
TEST(OrbitCamera, ValidateRefusesBeyondTheDeclaredRanges) {
  OrbitCamera camera;
  camera.distance = OrbitCamera::kMaxDistance;
  camera.pitch_degrees = OrbitCamera::kMaxPitchDegrees;
  EXPECT_NO_THROW(camera.validate());
  camera.distance = 1.01f * OrbitCamera::kMaxDistance;
  EXPECT_THROW(camera.validate(), std::invalid_argument);
  camera.distance = 2.0f;
  camera.pitch_degrees = OrbitCamera::kMaxPitchDegrees + 0.5f;
  EXPECT_THROW(camera.validate(), std::invalid_argument);
  camera.pitch_degrees = 0.0f;
  camera.field_of_view_degrees = OrbitCamera::kMinFieldOfView;
  EXPECT_NO_THROW(camera.validate());
  camera.field_of_view_degrees = OrbitCamera::kMaxFieldOfView;
  EXPECT_NO_THROW(camera.validate());
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float infinity = std::numeric_limits<float>::infinity();
  const auto refused = [](OrbitCamera bad, const char* what, float value) {
    EXPECT_THROW(bad.validate(), std::invalid_argument) << what << " " << value;
  };
  for (const float fov :
       {0.99f * OrbitCamera::kMinFieldOfView, 1.01f * OrbitCamera::kMaxFieldOfView, nan}) {
    OrbitCamera bad = camera;
    bad.field_of_view_degrees = fov;
    refused(bad, "field of view", fov);
  }
  for (const float yaw : {nan, infinity}) {
    OrbitCamera bad = camera;
    bad.yaw_degrees = yaw;
    refused(bad, "yaw", yaw);
  }
  for (const float distance : {0.0f, -1.0f, nan}) {
    OrbitCamera bad = camera;
    bad.distance = distance;
    refused(bad, "distance", distance);
  }
  for (int axis = 0; axis < 3; ++axis) {
    OrbitCamera bad = camera;
    bad.target[axis] = nan;
    refused(bad, "target axis", float(axis));
  }
  // A huge tank's farthest orbit stays within what validate() accepts.
  EXPECT_LE(orbit_limits({{0, 0, 0}, {100, 100, 100}}).max_distance, OrbitCamera::kMaxDistance);
}

// A point of the frame at a depth, back in the scene: projecting it again lands where it was, at
// that depth; the frame's centre lies on the line from the eye to the target.
TEST(OrbitCamera, UnprojectIsTheInverseOfTheProjection) {
  OrbitCamera camera;
  const glm::mat4 view = camera.view(), projection = camera.projection(0.5f);
  const glm::vec3 centre = unproject(view, projection, {0.5f, 0.5f}, camera.distance);
  EXPECT_LT(glm::distance(centre, camera.target), 1e-4f);
  const glm::vec2 screen(0.2f, 0.9f);  // left, near the bottom
  const glm::vec3 point = unproject(view, projection, screen, 1.7f);
  const glm::vec4 in_view = view * glm::vec4(point, 1.0f);
  EXPECT_NEAR(-in_view.z, 1.7f, 1e-4f);
  EXPECT_LT(in_view.x, 0.0f);  // left of the view axis
  EXPECT_LT(in_view.y, 0.0f);  // below it
  const glm::vec4 clip = projection * in_view;
  EXPECT_NEAR(0.5f * (clip.x / clip.w + 1.0f), screen.x, 1e-4f);
  EXPECT_NEAR(0.5f * (clip.y / clip.w + 1.0f), screen.y, 1e-4f);
  // Depth is kept from a twentieth of the way to the target (a finger's fluid close to the eye)
  // to far behind it.
  for (const float depth : {0.06f * camera.distance, 10.0f * camera.distance}) {
    const glm::vec4 at =
        projection * view * glm::vec4(unproject(view, projection, {0.5f, 0.5f}, depth), 1.0f);
    EXPECT_GE(at.z / at.w, 0.0f) << depth;
    EXPECT_LE(at.z / at.w, 1.0f) << depth;
  }
}

}  // namespace
}  // namespace fluidcast::render

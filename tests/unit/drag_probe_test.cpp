// The depth a drag holds the fluid at: the surface the probe found under the finger, else, after
// DragProbe::kProbeFrames frames without one, the camera's target depth; each drag afresh.
#include "session/drag_probe.h"

#include <gtest/gtest.h>

namespace fluidcast::server {
namespace {

float depth_of(glm::vec3 point, const render::OrbitCamera& camera) {
  return -(camera.view() * glm::vec4(point, 1.0f)).z;
}

TEST(DragProbe, HoldsTheFluidAtTheSurfaceTheProbeFound) {
  render::OrbitCamera camera;
  DragProbe drag;
  drag.start();
  const glm::vec2 finger(0.5f, 0.5f);
  EXPECT_FALSE(drag.point(finger, camera, 1.0f)) << "not before the probe answers";
  const glm::vec3 surface = camera.target + 0.3f * glm::normalize(camera.eye() - camera.target);
  drag.probed(surface, camera);
  const auto held = drag.point(finger, camera, 1.0f);
  ASSERT_TRUE(held);
  EXPECT_LT(glm::distance(held->point, surface), 1e-4f);
  EXPECT_EQ(held->drag, 1u);
  // The finger moves: the same depth, elsewhere.
  const auto moved = drag.point(glm::vec2(0.7f, 0.4f), camera, 1.0f);
  EXPECT_NEAR(depth_of(moved->point, camera), camera.distance - 0.3f, 1e-4f);
}

TEST(DragProbe, WithoutASurfaceTheTargetDepthAfterAFewFrames) {
  render::OrbitCamera camera;
  DragProbe drag;
  drag.start();
  for (int k = 0; k < DragProbe::kProbeFrames; ++k) {
    EXPECT_FALSE(drag.point(glm::vec2(0.5f), camera, 1.0f)) << k;
    drag.probed(std::nullopt, camera);
  }
  const auto held = drag.point(glm::vec2(0.5f), camera, 1.0f);
  ASSERT_TRUE(held);
  EXPECT_NEAR(depth_of(held->point, camera), camera.distance, 1e-4f);
}

TEST(DragProbe, EachDragStartsAfresh) {
  render::OrbitCamera camera;
  DragProbe drag;
  drag.start();
  drag.probed(camera.target, camera);
  ASSERT_TRUE(drag.point(glm::vec2(0.5f), camera, 1.0f));
  EXPECT_FALSE(drag.point(std::nullopt, camera, 1.0f)) << "the finger lifted";
  drag.start();
  EXPECT_FALSE(drag.point(glm::vec2(0.5f), camera, 1.0f)) << "a new drag waits for its probe";
  drag.probed(camera.target, camera);
  EXPECT_EQ(drag.point(glm::vec2(0.5f), camera, 1.0f)->drag, 2u);
}

}  // namespace
}  // namespace fluidcast::server

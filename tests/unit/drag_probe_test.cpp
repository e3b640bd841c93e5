// The depth a drag holds the fluid at: the surface the probe found under the finger, else, after
// DragProbe::kProbeFrames frames without one, the camera's target depth; each drag afresh; and a
// lifted drag's last point at its own depth, beside the next drag's.
#include "session/drag_probe.h"

#include <gtest/gtest.h>

namespace fluidcast::server {
namespace {

float depth_of(glm::vec3 point, const render::OrbitCamera& camera) {
  return -(camera.view() * glm::vec4(point, 1.0f)).z;
}

// The live drag's point, when the tick has no ended drag.
std::optional<DragProbe::DragPoint> live(DragProbe& drag, std::optional<glm::vec2> finger,
                                         const render::OrbitCamera& camera) {
  const DragProbe::Points points = drag.points(finger, camera, 1.0f);
  EXPECT_TRUE(points.ended.empty());
  return points.live;
}

TEST(DragProbe, HoldsTheFluidAtTheSurfaceTheProbeFound) {
  render::OrbitCamera camera;
  DragProbe drag;
  drag.start();
  const glm::vec2 finger(0.5f, 0.5f);
  EXPECT_FALSE(live(drag, finger, camera)) << "not before the probe answers";
  const glm::vec3 surface = camera.target + 0.3f * glm::normalize(camera.eye() - camera.target);
  drag.probed(drag.drag(), surface, camera);
  const auto held = live(drag, finger, camera);
  ASSERT_TRUE(held);
  EXPECT_LT(glm::distance(held->point, surface), 1e-4f);
  EXPECT_EQ(held->drag, 1u);
  // The finger moves: the same depth, elsewhere.
  const auto moved = live(drag, glm::vec2(0.7f, 0.4f), camera);
  EXPECT_NEAR(depth_of(moved->point, camera), camera.distance - 0.3f, 1e-4f);
}

TEST(DragProbe, WithoutASurfaceTheTargetDepthAfterAFewFrames) {
  render::OrbitCamera camera;
  DragProbe drag;
  drag.start();
  for (int k = 0; k < DragProbe::kProbeFrames; ++k) {
    EXPECT_FALSE(live(drag, glm::vec2(0.5f), camera)) << k;
    drag.probed(drag.drag(), std::nullopt, camera);
  }
  const auto held = live(drag, glm::vec2(0.5f), camera);
  ASSERT_TRUE(held);
  EXPECT_NEAR(depth_of(held->point, camera), camera.distance, 1e-4f);
}

TEST(DragProbe, EachDragStartsAfresh) {
  render::OrbitCamera camera;
  DragProbe drag;
  drag.start();
  drag.probed(drag.drag(), camera.target, camera);
  ASSERT_TRUE(live(drag, glm::vec2(0.5f), camera));
  EXPECT_FALSE(live(drag, std::nullopt, camera)) << "the finger lifted";
  drag.start();
  EXPECT_FALSE(live(drag, glm::vec2(0.5f), camera)) << "a new drag waits for its probe";
  drag.probed(drag.drag(), camera.target, camera);
  EXPECT_EQ(live(drag, glm::vec2(0.5f), camera)->drag, 2u);
}

// A finger lifted and the next came down before the tick: the tick has the lifted drag's last
// point, at the depth that drag held (before, the new drag had taken its place and the stroke's
// last stretch was never followed), then the new drag's once its probe answers.
TEST(DragProbe, ALiftedDragsLastPointComesBesideTheNextDrag) {
  render::OrbitCamera camera;
  DragProbe drag;
  drag.start();
  const glm::vec3 surface = camera.target + 0.3f * glm::normalize(camera.eye() - camera.target);
  drag.probed(drag.drag(), surface, camera);
  ASSERT_TRUE(live(drag, glm::vec2(0.5f), camera));
  drag.lift(glm::vec2(0.8f, 0.6f), camera, 1.0f);
  drag.start();
  const DragProbe::Points tick = drag.points(glm::vec2(0.2f), camera, 1.0f);
  EXPECT_FALSE(tick.live) << "the new drag waits for its probe";
  ASSERT_EQ(tick.ended.size(), 1u);
  EXPECT_EQ(tick.ended[0].drag, 1u);
  EXPECT_NEAR(depth_of(tick.ended[0].point, camera), camera.distance - 0.3f, 1e-4f);
  const glm::vec3 lifted_at = render::unproject(camera.view(), camera.projection(1.0f),
                                                glm::vec2(0.8f, 0.6f), camera.distance - 0.3f);
  EXPECT_LT(glm::distance(tick.ended[0].point, lifted_at), 1e-4f);
  // Given once; the new drag holds the camera's target once its probe has found nothing.
  for (int k = 0; k < DragProbe::kProbeFrames; ++k) drag.probed(drag.drag(), std::nullopt, camera);
  const auto next = live(drag, glm::vec2(0.2f), camera);
  ASSERT_TRUE(next);
  EXPECT_EQ(next->drag, 2u);
  EXPECT_NEAR(depth_of(next->point, camera), camera.distance, 1e-4f);
}

// A drag lifted before its probe answered has no point to give, as it had none while it lasted.
TEST(DragProbe, ADragLiftedBeforeItsProbeAnsweredGivesNothing) {
  render::OrbitCamera camera;
  DragProbe drag;
  drag.start();
  drag.lift(glm::vec2(0.5f), camera, 1.0f);
  EXPECT_TRUE(drag.points(std::nullopt, camera, 1.0f).ended.empty());
}

// A frame drawn for the drag before, back after the next began, answers nothing for the new one:
// its surface was under the other finger.
TEST(DragProbe, AFrameProbedForTheDragBeforeCountsForNothing) {
  render::OrbitCamera camera;
  DragProbe drag;
  drag.start();
  const std::uint64_t first = drag.drag();
  drag.start();
  const glm::vec3 elsewhere = camera.target + 0.3f * glm::normalize(camera.eye() - camera.target);
  for (int k = 0; k < DragProbe::kProbeFrames; ++k) drag.probed(first, elsewhere, camera);
  EXPECT_FALSE(live(drag, glm::vec2(0.5f), camera)) << "the new drag's probe has not answered";
  drag.probed(drag.drag(), camera.target, camera);
  const auto held = live(drag, glm::vec2(0.5f), camera);
  ASSERT_TRUE(held);
  EXPECT_NEAR(depth_of(held->point, camera), camera.distance, 1e-4f);
}

}  // namespace
}  // namespace fluidcast::server

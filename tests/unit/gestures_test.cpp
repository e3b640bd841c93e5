// Pointer events to gestures: one finger drags, two orbit and zoom, and a finger left behind
// after two does not drag; a view-only viewer's one finger orbits.
#include "session/gestures.h"

#include <gtest/gtest.h>

namespace fluidcast::server {
namespace {

v1::PointerEvent pointer(std::uint32_t id, v1::PointerEvent::Phase phase, float x, float y) {
  v1::PointerEvent event;
  event.set_pointer_id(id);
  event.set_phase(phase);
  event.set_x(x);
  event.set_y(y);
  return event;
}

TEST(GesturesTest, OneFingerDragsWhereItIs) {
  Gestures gestures(true);
  EXPECT_FALSE(gestures.drag());
  EXPECT_TRUE(gestures.apply(pointer(3, v1::PointerEvent::DOWN, 0.2f, 0.4f)).drag_started);
  const GestureChange move = gestures.apply(pointer(3, v1::PointerEvent::MOVE, 0.3f, 0.5f));
  EXPECT_EQ(move.yaw_degrees, 0.0f) << "a finger dragging the fluid does not orbit";
  EXPECT_EQ(move.pitch_degrees, 0.0f);
  ASSERT_TRUE(gestures.drag());
  EXPECT_FLOAT_EQ(gestures.drag()->x, 0.3f);
  EXPECT_FLOAT_EQ(gestures.drag()->y, 0.5f);
  const GestureChange lift = gestures.apply(pointer(3, v1::PointerEvent::UP, 0.3f, 0.5f));
  ASSERT_TRUE(lift.drag_ended_at);
  EXPECT_FALSE(gestures.drag());
}

// A drag ends where its finger lifted: an UP's own point (the hand may have moved since its last
// move), a cancel's last move (its own point carries nothing the hand did), and where it was when
// a second finger joined; the fingers that lift after that end no drag (none was on).
TEST(GesturesTest, ADragEndsWhereItsFingerLifted) {
  Gestures gestures(true);
  gestures.apply(pointer(3, v1::PointerEvent::DOWN, 0.2f, 0.4f));
  gestures.apply(pointer(3, v1::PointerEvent::MOVE, 0.4f, 0.5f));
  const auto up = gestures.apply(pointer(3, v1::PointerEvent::UP, 0.6f, 0.7f)).drag_ended_at;
  ASSERT_TRUE(up);
  EXPECT_FLOAT_EQ(up->x, 0.6f);
  EXPECT_FLOAT_EQ(up->y, 0.7f);

  gestures.apply(pointer(4, v1::PointerEvent::DOWN, 0.1f, 0.1f));
  gestures.apply(pointer(4, v1::PointerEvent::MOVE, 0.2f, 0.3f));
  const auto cancel =
      gestures.apply(pointer(4, v1::PointerEvent::CANCEL, 0.0f, 0.0f)).drag_ended_at;
  ASSERT_TRUE(cancel);
  EXPECT_FLOAT_EQ(cancel->x, 0.2f);
  EXPECT_FLOAT_EQ(cancel->y, 0.3f);

  gestures.apply(pointer(5, v1::PointerEvent::DOWN, 0.5f, 0.5f));
  gestures.apply(pointer(5, v1::PointerEvent::MOVE, 0.55f, 0.5f));
  const auto joined = gestures.apply(pointer(6, v1::PointerEvent::DOWN, 0.7f, 0.7f)).drag_ended_at;
  ASSERT_TRUE(joined);
  EXPECT_FLOAT_EQ(joined->x, 0.55f);
  EXPECT_FALSE(gestures.apply(pointer(5, v1::PointerEvent::UP, 0.5f, 0.5f)).drag_ended_at);
  EXPECT_FALSE(gestures.apply(pointer(6, v1::PointerEvent::UP, 0.7f, 0.7f)).drag_ended_at);
  EXPECT_FALSE(gestures.drag());

  // A finger that comes down again without its UP (lost): the drag before ends where it was.
  gestures.apply(pointer(7, v1::PointerEvent::DOWN, 0.1f, 0.2f));
  const GestureChange again = gestures.apply(pointer(7, v1::PointerEvent::DOWN, 0.8f, 0.9f));
  EXPECT_TRUE(again.drag_started);
  ASSERT_TRUE(again.drag_ended_at);
  EXPECT_FLOAT_EQ(again.drag_ended_at->x, 0.1f);
}

TEST(GesturesTest, TwoFingersOrbitAndZoomAndTheOneLeftDoesNotDrag) {
  Gestures gestures(true);
  gestures.apply(pointer(0, v1::PointerEvent::DOWN, 0.4f, 0.5f));
  EXPECT_FALSE(gestures.apply(pointer(1, v1::PointerEvent::DOWN, 0.6f, 0.5f)).drag_started);
  EXPECT_FALSE(gestures.drag());
  // Both move right by 0.1: the centre moves 0.05 → yaw −9°.
  const GestureChange orbit = gestures.apply(pointer(1, v1::PointerEvent::MOVE, 0.7f, 0.5f));
  EXPECT_NEAR(orbit.yaw_degrees, -0.05f * Gestures::kOrbitDegreesPerFrame, 1e-4f);
  EXPECT_NEAR(orbit.zoom, 0.2f / 0.3f, 1e-5f);  // spread 0.2 → 0.3: closer
  const GestureChange pinch = gestures.apply(pointer(0, v1::PointerEvent::MOVE, 0.5f, 0.5f));
  EXPECT_NEAR(pinch.zoom, 0.3f / 0.2f, 1e-5f);
  gestures.apply(pointer(1, v1::PointerEvent::UP, 0.7f, 0.5f));
  EXPECT_FALSE(gestures.drag());
  gestures.apply(pointer(0, v1::PointerEvent::UP, 0.5f, 0.5f));
  EXPECT_TRUE(gestures.apply(pointer(0, v1::PointerEvent::DOWN, 0.5f, 0.5f)).drag_started);
  EXPECT_TRUE(gestures.drag());
}

// A pinch zooms by at most a factor of two a move, and fingers that came down on one point (no
// spread to compare with) do not zoom at all.
TEST(GesturesTest, APinchZoomsByAtMostTwiceAMove) {
  Gestures gestures(true);
  gestures.apply(pointer(0, v1::PointerEvent::DOWN, 0.5f, 0.5f));
  gestures.apply(pointer(1, v1::PointerEvent::DOWN, 0.5f, 0.5f));
  EXPECT_EQ(gestures.apply(pointer(1, v1::PointerEvent::MOVE, 0.55f, 0.5f)).zoom, 1.0f);
  EXPECT_EQ(gestures.apply(pointer(1, v1::PointerEvent::MOVE, 0.95f, 0.5f)).zoom, 0.5f);
  EXPECT_EQ(gestures.apply(pointer(1, v1::PointerEvent::MOVE, 0.55f, 0.5f)).zoom, 2.0f);
}

TEST(GesturesTest, MovesOfUnknownPointersAreIgnored) {
  Gestures gestures(true);
  const GestureChange change = gestures.apply(pointer(5, v1::PointerEvent::MOVE, 0.5f, 0.5f));
  EXPECT_FALSE(change.drag_started);
  EXPECT_FALSE(gestures.drag());
}

TEST(GesturesTest, AViewerThatMayNotTouchTheFluidOrbitsWithOneFinger) {
  Gestures gestures(false);
  EXPECT_FALSE(gestures.apply(pointer(0, v1::PointerEvent::DOWN, 0.4f, 0.5f)).drag_started);
  const GestureChange orbit = gestures.apply(pointer(0, v1::PointerEvent::MOVE, 0.5f, 0.4f));
  EXPECT_NEAR(orbit.yaw_degrees, -0.1f * Gestures::kOrbitDegreesPerFrame, 1e-4f);
  EXPECT_NEAR(orbit.pitch_degrees, -0.1f * Gestures::kOrbitDegreesPerFrame, 1e-4f);
  EXPECT_FALSE(gestures.drag());
}

}  // namespace
}  // namespace fluidcast::server

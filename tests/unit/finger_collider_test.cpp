// A dragging finger's sphere: in simulated time it never moves faster than the hand did in wall
// time, however slowly the fluid runs; in real time it keeps up with the finger; it reaches a
// finger that stopped without passing it.
#include "fluidcast/sim/finger_collider.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace fluidcast::sim {
namespace {

constexpr double kTick = 1.0 / 60.0;  // the session's ticks, wall seconds

// A hand sweeping to and fro, 0.3 m either side, 0.9 m/s at its fastest, its touch events
// arriving 20 times a second (every third tick): the finger's point at tick k.
glm::vec3 swept_finger(int k) {
  const double t = kTick * double(k - k % 3);
  return {0.3f * float(std::sin(3.0 * t)), 0.2f, 0.1f};
}
constexpr float kFastestHand = 0.9f;

struct Sweep {
  float fastest_sphere = 0.0f;  // m/s in simulated time
  float widest_gap = 0.0f;      // m, between the finger and where the sphere ends a tick
};

// `ticks` ticks of the sweep with the fluid at `sim_speed` of real time.
Sweep sweep(FingerCollider& finger, int first, int ticks, double sim_speed) {
  Sweep run;
  for (int k = first; k < first + ticks; ++k) {
    const glm::vec3 target = swept_finger(k);
    const auto motion = finger.follow(target, sim_speed * kTick, kTick);
    run.fastest_sphere = std::max(run.fastest_sphere, glm::length(motion.velocity));
    const glm::vec3 end = motion.centre + motion.velocity * float(sim_speed * kTick);
    run.widest_gap = std::max(run.widest_gap, glm::distance(end, target));
  }
  return run;
}

TEST(FingerCollider, InSlowMotionMovesNoFasterThanTheHand) {
  for (const double sim_speed : {0.5, 0.1, 0.02}) {
    FingerCollider finger(swept_finger(0));
    const Sweep run = sweep(finger, 0, 600, sim_speed);
    // Chasing the finger over each tick's wall time made the sphere 1/sim_speed times faster than
    // the hand: 45 m/s at 0.02.
    EXPECT_LE(run.fastest_sphere, 1.05f * kFastestHand) << "at " << sim_speed << " of real time";
    EXPECT_GT(run.fastest_sphere, 0.5f * kFastestHand) << "it follows at " << sim_speed;
    EXPECT_LE(finger.hand_speed(), 1.05f * kFastestHand);
  }
}

TEST(FingerCollider, InRealTimeKeepsUpWithTheFinger) {
  FingerCollider finger(swept_finger(0));
  sweep(finger, 0, 60, 1.0);  // the hand's fastest is known after its first pass
  const Sweep run = sweep(finger, 60, 600, 1.0);
  // Touch events 50 ms apart leave the finger up to 4.5 cm ahead between them.
  EXPECT_LE(run.widest_gap, 0.06f);
  EXPECT_LE(run.fastest_sphere, 1.05f * kFastestHand);
}

TEST(FingerCollider, ReachesAFingerThatStoppedWithoutPassingIt) {
  FingerCollider finger(swept_finger(0));
  const double sim_speed = 0.05;
  const int moving = 100;  // the hand sweeps for 1.7 s, then rests where it is
  sweep(finger, 0, moving, sim_speed);
  const glm::vec3 rest = swept_finger(moving);
  const float hand = finger.hand_speed();
  const float first_gap = glm::distance(finger.follow(rest, 0.0, kTick).centre, rest);
  ASSERT_GT(first_gap, 0.1f) << "the sphere trails the hand when it stops";
  EXPECT_FALSE(finger.arrived());
  // At the hand's fastest, in simulated time.
  const int expected = int(std::ceil(first_gap / (hand * float(sim_speed * kTick))));
  float gap = first_gap;
  int ticks = 0;
  while (ticks < 2 * expected && gap > 0.0f) {
    const auto motion = finger.follow(rest, sim_speed * kTick, kTick);
    const glm::vec3 end = motion.centre + motion.velocity * float(sim_speed * kTick);
    ASSERT_GE(glm::dot(end - motion.centre, rest - end), -1e-9f) << "past the finger";
    const float next_gap = glm::distance(end, rest);
    ASSERT_LT(next_gap, gap) << "stalled at tick " << ticks;
    gap = next_gap;
    ++ticks;
    if (gap < 1e-6f) break;
  }
  EXPECT_LT(gap, 1e-6f);
  EXPECT_LE(ticks, expected + 1);
  EXPECT_TRUE(finger.arrived());
}

TEST(FingerCollider, FollowsAFlickAfterARest) {
  const glm::vec3 start(0.1f, 0.2f, 0.3f);
  FingerCollider finger(start);
  for (int k = 0; k < 60; ++k) finger.follow(start, kTick, kTick);  // held still for a second
  // Then 0.45 m in 0.15 s (3 m/s), one touch event every third tick.
  for (int k = 1; k <= 9; ++k) {
    const float along = 0.05f * float(k - k % 3);
    finger.follow(start + glm::vec3(along, 0.0f, 0.0f), kTick, kTick);
  }
  // Measured from the rest, the first move would count as 0.45 m in 1.15 s: 0.4 m/s.
  EXPECT_GT(finger.hand_speed(), 2.5f);
  EXPECT_LT(finger.hand_speed(), 3.5f);
}

TEST(FingerCollider, GrowsToItsRadiusOverATenthOfASimulatedSecond) {
  const glm::vec3 start(0.1f, 0.2f, 0.3f);
  FingerCollider paused(start);
  const auto before_any_step = paused.follow(start, 0.0, kTick);
  EXPECT_EQ(before_any_step.size, 0.0f) << "not in a paused fluid yet";
  EXPECT_FALSE(before_any_step.collider(0.05f)) << "no collider of radius 0";
  // In slow motion, over simulated time: a tenth of real time takes ten times the ticks.
  for (const double sim_speed : {1.0, 0.1}) {
    FingerCollider finger(start);
    const int ticks = int(std::lround(FingerCollider::kGrowSeconds / (sim_speed * kTick)));
    float size = 0.0f;
    for (int k = 1; k <= ticks + 2; ++k) {
      const float next = finger.follow(start, sim_speed * kTick, kTick).size;
      ASSERT_GT(next, size) << "grows at tick " << k;
      if (k <= ticks) {
        EXPECT_NEAR(next, float(k) / float(ticks), 1e-4f) << k;
      }
      size = next;
      if (size == 1.0f) break;
    }
    EXPECT_EQ(size, 1.0f);
  }
}

TEST(FingerCollider, StartsAtTheFingerAndStaysFiniteWhateverTheTimes) {
  const glm::vec3 start(0.1f, 0.2f, 0.3f);
  FingerCollider finger(start);
  auto motion = finger.follow(start, kTick, kTick);
  EXPECT_EQ(motion.centre, start);
  EXPECT_EQ(motion.velocity, glm::vec3(0.0f));
  // A hand that flicks 1 km in a tick: held to kFastest.
  const glm::vec3 far = start + glm::vec3(1000.0f, 0.0f, 0.0f);
  motion = finger.follow(far, kTick, kTick);
  EXPECT_NEAR(glm::length(motion.velocity), FingerCollider::kFastest, 1e-2f);
  // Paused (no simulated time), or times that are not numbers: it stays where it is.
  const glm::vec3 before = finger.centre();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  for (const auto& [seconds, elapsed] : {std::pair{0.0, kTick}, std::pair{nan, kTick},
                                         std::pair{inf, kTick}, std::pair{-kTick, kTick}}) {
    motion = finger.follow(far, seconds, elapsed);
    EXPECT_EQ(motion.velocity, glm::vec3(0.0f)) << seconds;
    EXPECT_EQ(finger.centre(), before) << seconds;
  }
  // Wall times that are not numbers count as none: the hand's speed and the sphere stay finite.
  for (int k = 0; k < 100; ++k) {
    motion = finger.follow(start + glm::vec3(0.01f * float(k), 0.0f, 0.0f), kTick, nan);
    ASSERT_TRUE(std::isfinite(finger.hand_speed()));
    ASSERT_TRUE(is_finite(motion.velocity) && is_finite(finger.centre()));
  }
}

// Wall time that runs backwards counts as none: a hand that moved 0.05 m, then 0.25 m more, in
// events 0.1 s apart moved 0.3 m over 0.15 s (the first move taken as begun 50 ms before it was
// seen): 2 m/s, whatever a tick between its events said. Counting that tick's −10 s made it 6.
TEST(FingerCollider, WallTimeRunningBackwardsCountsAsNone) {
  const glm::vec3 start(0.1f, 0.2f, 0.3f);
  FingerCollider finger(start);
  finger.follow(start + glm::vec3(0.05f, 0.0f, 0.0f), kTick, 0.1);
  finger.follow(start + glm::vec3(0.05f, 0.0f, 0.0f), kTick, -10.0);
  finger.follow(start + glm::vec3(0.3f, 0.0f, 0.0f), kTick, 0.1);
  EXPECT_NEAR(finger.hand_speed(), 2.0f, 1e-4f);
}

// A finger that moves while the fluid is paused leaves a sphere that has not arrived: a lifted
// finger's sphere finishes its stroke once the fluid runs again.
TEST(FingerCollider, AFingerMovedWhilePausedHasNotArrived) {
  const glm::vec3 start(0.1f, 0.2f, 0.3f);
  FingerCollider finger(start);
  finger.follow(start, kTick, kTick);  // a running tick where the finger is: arrived
  ASSERT_TRUE(finger.arrived());
  finger.follow(start + glm::vec3(0.1f, 0.0f, 0.0f), 0.0, kTick);
  EXPECT_FALSE(finger.arrived());
}

}  // namespace
}  // namespace fluidcast::sim

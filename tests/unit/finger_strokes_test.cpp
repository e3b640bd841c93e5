// A session's finger spheres: a stroke whose finger lifted finishes beside the next one of the
// same viewer; live drags keep their place under the solver's cap.
#include "session/finger_strokes.h"

#include <gtest/gtest.h>

#include <vector>

namespace fluidcast::server {
namespace {

constexpr float kRadius = 0.05f;
constexpr double kTick = 1.0 / 60.0;

// Ticks at a tenth of real time: the spheres trail the fingers.
std::vector<sim::Collider> tick(FingerStrokes& strokes,
                                const std::vector<FingerStrokes::Finger>& live) {
  return strokes.move(live, 0.1 * kTick, kTick, kRadius);
}

// A stroke of viewer 1 from x = 0.2 to 0.8 m in 0.2 s of wall time (3 m/s), then lifted.
void stroke(FingerStrokes& strokes, std::uint64_t drag) {
  for (int k = 0; k <= 12; ++k) {
    tick(strokes, {{1, drag, glm::vec3(0.2f + 0.05f * float(k), 0.1f, 0.1f)}});
  }
}

TEST(FingerStrokes, ALiftedStrokeFinishesBesideTheNextOne) {
  FingerStrokes strokes;
  stroke(strokes, 1);
  // In slow motion the first sphere is far behind its finger when the second stroke begins.
  const auto both = tick(strokes, {{1, 2, glm::vec3(0.5f, 0.3f, 0.1f)}});
  ASSERT_EQ(strokes.size(), 2u);
  ASSERT_EQ(both.size(), 2u);  // the new sphere has begun to grow in, the old goes on
  EXPECT_LT(both[1].centre.x, 0.7f);
  // It reaches the first finger's last point, then is gone; the live one stays.
  float finished_at = 0.0f;
  for (int k = 0; k < 2000 && strokes.size() == 2; ++k) {
    const auto colliders = tick(strokes, {{1, 2, glm::vec3(0.5f, 0.3f, 0.1f)}});
    if (colliders.size() == 2) {  // where the old sphere ends the tick
      finished_at = colliders[1].centre.x + colliders[1].velocity.x * float(0.1 * kTick);
    }
  }
  ASSERT_EQ(strokes.size(), 1u);
  EXPECT_NEAR(finished_at, 0.8f, 1e-4f) << "its last tick ends where the finger lifted";
  EXPECT_EQ(tick(strokes, {{1, 2, glm::vec3(0.5f, 0.3f, 0.1f)}}).size(), 1u);
}

TEST(FingerStrokes, LiveDragsComeFirstUnderTheCap) {
  FingerStrokes strokes;
  // Sixteen viewers' strokes, lifted far from their spheres.
  std::vector<FingerStrokes::Finger> fingers;
  for (std::uint32_t v = 0; v < sim::kMaxColliders; ++v) {
    fingers.push_back({v, 1, glm::vec3(0.1f, 0.1f, 0.1f)});
  }
  tick(strokes, fingers);
  for (auto& finger : fingers) finger.point.x = 1.0f;
  tick(strokes, fingers);
  tick(strokes, {});
  ASSERT_EQ(strokes.size(), sim::kMaxColliders);
  // A seventeenth viewer puts a finger down: its sphere is kept, one finishing stroke goes.
  tick(strokes, {{99, 1, glm::vec3(0.5f, 0.5f, 0.5f)}});
  const auto colliders = tick(strokes, {{99, 1, glm::vec3(0.5f, 0.5f, 0.5f)}});
  ASSERT_EQ(strokes.size(), sim::kMaxColliders);
  ASSERT_FALSE(colliders.empty());
  EXPECT_EQ(colliders.front().centre, glm::vec3(0.5f, 0.5f, 0.5f));
}

TEST(FingerStrokes, ClearedForANewFluid) {
  FingerStrokes strokes;
  stroke(strokes, 1);
  ASSERT_EQ(strokes.size(), 1u);
  strokes.clear();
  EXPECT_EQ(strokes.size(), 0u);
  EXPECT_TRUE(tick(strokes, {}).empty());
}

}  // namespace
}  // namespace fluidcast::server

#include "fluidcast/sim/scene.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <set>
#include <tuple>

namespace fluidcast::sim {
namespace {

Box bounds(const ParticleSet& p) {
  Box b{p.position[0], p.position[0]};
  for (const auto& x : p.position) {
    b.min = glm::min(b.min, x);
    b.max = glm::max(b.max, x);
  }
  return b;
}

TEST(Scene, EverySceneHasExactlyTheRequestedCountInsideTheTank) {
  for (auto name : scene_names()) {
    for (int n : {1, 10, 999, 5000}) {
      SceneParams p;
      p.kind = parse_scene(name);
      p.particles = n;
      const Scene s = build_scene(p);
      ASSERT_EQ(s.particles.size(), std::size_t(n)) << name;
      std::set<std::uint32_t> ids(s.particles.id.begin(), s.particles.id.end());
      EXPECT_EQ(ids.size(), std::size_t(n));
      for (const auto& x : s.particles.position) ASSERT_TRUE(s.tank.contains(x)) << name;
    }
  }
}

// A count that leaves the top layer partly filled spreads it over the layer: the water's centre
// of mass lies over the tank's middle (filled from a corner, 1000 particles had it 0.09 and 0.12
// spacings off in x and z, and the pool started with a wave), and no two particles share a site.
// 1155 is 6 whole layers of 32 × 6 and three more.
TEST(Scene, APartlyFilledTopLayerIsSpreadOverIt) {
  for (int n : {777, 1000, 1155, 2000, 10000}) {
    SceneParams p;
    p.kind = SceneKind::pool;
    p.particles = n;
    const Scene s = build_scene(p);
    glm::dvec3 sum(0.0);
    std::set<std::tuple<float, float, float>> sites;
    for (const glm::vec3& x : s.particles.position) {
      sum += glm::dvec3(x);
      sites.insert({x.x, x.y, x.z});
    }
    EXPECT_EQ(sites.size(), static_cast<std::size_t>(n)) << "particles sharing a site";
    const glm::dvec3 centre = sum / static_cast<double>(n);
    const glm::vec3 middle = 0.5f * (s.tank.min + s.tank.max);
    EXPECT_NEAR(centre.x, middle.x, 0.02 * s.spacing) << n << " particles";
    EXPECT_NEAR(centre.z, middle.z, 0.02 * s.spacing) << n << " particles";
  }
}

// A handful of particles would fill the water's volume at a spacing wider than the tank is deep
// (which no solver takes): theirs is capped, and they make a smaller puddle.
TEST(Scene, AFewParticlesSpaceNoWiderThanHalfTheThinnestSide) {
  for (auto name : scene_names()) {
    for (int n = 1; n <= 8; ++n) {
      SceneParams p;
      p.kind = parse_scene(name);
      p.particles = n;
      const Scene s = build_scene(p);
      const glm::vec3 size = s.tank.size();
      EXPECT_LE(s.spacing, 0.5f * std::min({size.x, size.y, size.z}) + 1e-6f) << name << " " << n;
      EXPECT_EQ(s.particles.size(), std::size_t(n)) << name;
    }
  }
}

TEST(Scene, DamBreakColumnStandsAgainstTheLeftWallAndFillsTheDepth) {
  SceneParams p;
  p.particles = 20000;
  const Scene s = build_scene(p);
  const Box b = bounds(s.particles);
  const float d = s.spacing;
  // Half a lattice spacing (within 10 % of d) from each wall it touches.
  EXPECT_NEAR(b.min.x, 0.5f * d, 0.05f * d);
  EXPECT_NEAR(p.column_width - b.max.x, 0.5f * d, 0.05f * d);
  EXPECT_NEAR(b.min.z, 0.5f * d, 0.05f * d);
  EXPECT_NEAR(p.depth - b.max.z, 0.5f * d, 0.05f * d);
  EXPECT_NEAR(b.min.y, 0.5f * d, 0.05f * d);
  EXPECT_NEAR(b.max.y, p.column_height, d);
  EXPECT_NEAR(d * d * d * 20000, p.column_width * p.column_height * p.depth, 1e-6);
}

TEST(Scene, DoubleDamBreakHasAColumnAtEachEnd) {
  SceneParams p;
  p.kind = SceneKind::double_dam_break;
  p.particles = 4000;
  const Scene s = build_scene(p);
  int left = 0, right = 0;
  for (const auto& x : s.particles.position) {
    if (x.x < p.column_width) ++left;
    if (x.x > p.tank_length - p.column_width) ++right;
  }
  EXPECT_EQ(left + right, 4000);
  EXPECT_EQ(left, 2000);
}

TEST(Scene, DropHasABallAboveThePool) {
  SceneParams p;
  p.kind = SceneKind::drop;
  p.particles = 8000;
  const Scene s = build_scene(p);
  int above = 0;
  for (const auto& x : s.particles.position) above += x.y > p.pool_height;
  const float ball = 4.0f / 3.0f * 3.14159f * std::pow(p.drop_radius, 3.0f);
  const float pool = p.tank_length * p.depth * p.pool_height;
  EXPECT_NEAR(above, 8000 * ball / (ball + pool), 0.1 * 8000 * ball / (ball + pool));
}

TEST(Scene, GeometryThatDoesNotFitIsRefused) {
  SceneParams p;
  p.column_width = 2.0f;
  EXPECT_THROW(build_scene(p), ParamError);
  p = SceneParams{};
  p.kind = SceneKind::drop;
  p.drop_height = 0.35f;
  EXPECT_THROW(build_scene(p), ParamError);
  p = SceneParams{};
  p.particles = -5;
  EXPECT_THROW(build_scene(p), ParamError);
}

// Each scene's own rule of fit, broken alone, is refused naming the flag that breaks it. (A drop's
// pool is below its ball, which is below the lid: the pool's own rule follows from the ball's.)
TEST(Scene, EachRuleOfFitNamesItsFlag) {
  struct Case {
    SceneKind kind;
    void (*set)(SceneParams&);
    const char* flag;
  };
  const Case cases[] = {
      {SceneKind::dam_break, [](SceneParams& p) { p.column_width = p.tank_length; },
       "column-width"},
      {SceneKind::dam_break, [](SceneParams& p) { p.column_height = 1.01f * p.tank_height; },
       "column-height"},
      {SceneKind::double_dam_break, [](SceneParams& p) { p.column_width = 0.5f * p.tank_length; },
       "column-width"},
      {SceneKind::double_dam_break, [](SceneParams& p) { p.column_height = 1.01f * p.tank_height; },
       "column-height"},
      {SceneKind::drop,
       [](SceneParams& p) { p.drop_height = p.tank_height - 0.5f * p.drop_radius; }, "drop-height"},
      {SceneKind::drop, [](SceneParams& p) { p.drop_height = 0.35f; }, "drop-height"},
      {SceneKind::drop, [](SceneParams& p) { p.drop_radius = 0.51f * p.depth; }, "drop-radius"},
      {SceneKind::pool, [](SceneParams& p) { p.pool_height = p.tank_height; }, "pool-height"},
  };
  for (const Case& c : cases) {
    SceneParams p;
    p.kind = c.kind;
    p.particles = 1000;
    c.set(p);
    SCOPED_TRACE(to_string(c.kind));
    SCOPED_TRACE(c.flag);
    try {
      build_scene(p);
      ADD_FAILURE() << "built";
    } catch (const ParamError& e) {
      const std::string worded = e.worded([](std::string_view name) { return std::string(name); });
      EXPECT_EQ(worded.rfind(c.flag, 0), 0u) << worded;
    }
  }
  SceneParams fits;  // a double dam break's columns just fit, at a little under half the tank each
  fits.kind = SceneKind::double_dam_break;
  fits.particles = 1000;
  fits.column_width = 0.49f * fits.tank_length;
  EXPECT_NO_THROW(build_scene(fits));
}

// A drop of very few particles keeps one in its pool: the ball never takes them all (one particle:
// the pool's; a few: one in the ball, the rest in the pool).
TEST(Scene, ADropOfAFewParticlesKeepsOneInItsPool) {
  for (int n : {1, 2, 10, 50}) {
    SceneParams p;
    p.kind = SceneKind::drop;
    p.particles = n;
    const Scene s = build_scene(p);
    int in_pool = 0;
    for (const glm::vec3& x : s.particles.position) in_pool += x.y < p.pool_height ? 1 : 0;
    EXPECT_GE(in_pool, 1) << n;
  }
}

}  // namespace
}  // namespace fluidcast::sim

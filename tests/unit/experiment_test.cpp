// The pieces of the validation against experiment (tools/fluidcast-validate): the density, spray
// and surge-front measures, Martin & Moyce's variables and time shift, and the comparison.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "fluidcast/sim/statistics.h"
#include "martin_moyce.h"
#include "svg_plot.h"

namespace fluidcast::validation {
namespace {

const sim::Box kTank{glm::vec3(0.0f), glm::vec3(2.0f, 1.0f, 0.1f)};
constexpr float kSpacing = 0.01f;

// Every scene starts as a cubic lattice half a spacing from the walls: it measures ρ0 at every
// site, against a wall, along an edge and in a corner too, as the solvers count density (the
// walls' fluid included). At h = 2d an edge's first site reads 0.6 % under, a corner's 1.4 %;
// with the walls left out, a site against a wall reads 19 % under, an edge's 35 %, a corner's 48 %.
TEST(MeasureDensities, ALatticeFillingATankReadsRestDensityAtEverySite) {
  const sim::FluidConstants fluid = sim::derive_fluid_constants(kSpacing, sim::SolverParams{});
  const glm::ivec3 sites(12, 10, 8);
  const sim::Box tank{glm::vec3(0.0f), glm::vec3(sites) * kSpacing};
  sim::ParticleSet lattice;
  for (int k = 0; k < sites.z; ++k)
    for (int j = 0; j < sites.y; ++j)
      for (int i = 0; i < sites.x; ++i)
        lattice.append((glm::vec3(i, j, k) + 0.5f) * kSpacing, glm::vec3(0.0f),
                       static_cast<std::uint32_t>(lattice.size()));
  const std::vector<float> density = sim::measure_densities(lattice, fluid, tank);
  for (std::size_t p = 0; p < lattice.size(); ++p) {
    const glm::vec3 x = lattice.position[p];
    const float ratio = density[p] / fluid.rest_density;
    EXPECT_TRUE(ratio > 0.98f && ratio < 1.01f)
        << "ρ/ρ0 = " << ratio << " at (" << x.x << ", " << x.y << ", " << x.z << ") m";
  }
}

// Spray: a particle with fewer than 6 others within two spacings. A block of water has none, even
// at its corners (10 there); a thread of particles (2 to 4 each) and a lone drop are all spray.
// Sites 0.95 d apart: none lies exactly two spacings from another, where rounding would decide.
// Also with the shortest kernel (h = 1.5 d), whose grid alone would not reach two spacings.
class MeasureSpray : public ::testing::TestWithParam<float> {};

TEST_P(MeasureSpray, DropsAndThreadsAreSprayABlockIsNot) {
  sim::SolverParams params;
  params.kernel_ratio = GetParam();
  const sim::FluidConstants fluid = sim::derive_fluid_constants(kSpacing, params);
  const float apart = 0.95f * kSpacing;
  sim::ParticleSet water;
  for (int k = 0; k < 6; ++k)
    for (int j = 0; j < 6; ++j)
      for (int i = 0; i < 6; ++i)
        water.append(glm::vec3(0.02f) + glm::vec3(i, j, k) * apart, glm::vec3(0.0f),
                     static_cast<std::uint32_t>(water.size()));
  EXPECT_EQ(sim::measure(water, fluid, kTank).spray_share, 0.0);

  for (int i = 0; i < 10; ++i) {
    water.append({1.2f + i * apart, 0.7f, 0.05f}, glm::vec3(0.0f), 1000u + i);
  }
  water.append({1.8f, 0.3f, 0.05f}, glm::vec3(0.0f), 2000u);
  EXPECT_DOUBLE_EQ(sim::measure(water, fluid, kTank).spray_share, 11.0 / 227.0);

  // A loose block, 1.8 d apart: inside, each has its 6 nearest within reach, and is water; on its
  // faces, edges and corners 5, 4 or 3: spray.
  sim::ParticleSet loose;
  for (int k = 0; k < 5; ++k)
    for (int j = 0; j < 5; ++j)
      for (int i = 0; i < 5; ++i)
        loose.append(glm::vec3(0.02f) + glm::vec3(i, j, k) * 1.8f * kSpacing, glm::vec3(0.0f),
                     static_cast<std::uint32_t>(loose.size()));
  EXPECT_DOUBLE_EQ(sim::measure(loose, fluid, kTank).spray_share, (125.0 - 27.0) / 125.0);
}

INSTANTIATE_TEST_SUITE_P(KernelRatios, MeasureSpray, ::testing::Values(2.0f, 1.5f));

sim::ParticleSet floor_layer(float from, float to) {
  sim::ParticleSet set;
  for (float x = from; x <= to + 1e-6f; x += kSpacing) {
    set.append({x, 0.005f, 0.05f}, glm::vec3(0.0f), static_cast<std::uint32_t>(set.size()));
  }
  return set;
}

// The water's edge: half a spacing beyond the last centre.
TEST(SurgeFront, IsTheFarEndOfTheLayerOnTheFloor) {
  const sim::ParticleSet layer = floor_layer(0.005f, 0.505f);
  EXPECT_NEAR(sim::surge_front(layer, kSpacing, kTank), 0.51, 1e-5);
}

TEST(SurgeFront, IgnoresADropletAheadAndSprayAbove) {
  sim::ParticleSet set = floor_layer(0.005f, 0.505f);
  set.append({0.9f, 0.005f, 0.05f}, glm::vec3(0.0f), 1000);  // a droplet 0.4 m ahead
  set.append({1.5f, 0.5f, 0.05f}, glm::vec3(0.0f), 1001);    // spray in the air
  EXPECT_NEAR(sim::surge_front(set, kSpacing, kTank), 0.51, 1e-5);
  // A particle that closes the gap to within a bin joins the layer.
  set.append({0.53f, 0.01f, 0.05f}, glm::vec3(0.0f), 1002);
  EXPECT_NEAR(sim::surge_front(set, kSpacing, kTank), 0.535, 1e-5);
}

// The band and the bins are two spacings: a particle three spacings up, one below the floor, or a
// droplet with an empty bin before it (four spacings on) is not the front.
TEST(SurgeFront, CountsOnlyTheFloorBandsUnbrokenRun) {
  for (const glm::vec3 ignored : {glm::vec3(0.525f, 0.03f, 0.05f), glm::vec3(0.525f, -0.01f, 0.05f),
                                  glm::vec3(0.545f, 0.005f, 0.05f)}) {
    sim::ParticleSet set = floor_layer(0.005f, 0.505f);
    set.append(ignored, glm::vec3(0.0f), 1000);
    EXPECT_NEAR(sim::surge_front(set, kSpacing, kTank), 0.51, 1e-5)
        << ignored.x << ", " << ignored.y;
  }
}

// What measure() adds up, on a few particles far apart: ½ m v² and the centre over the finite
// particles (one outside the tank among them, counted), a NaN one counted apart; no compression
// where the fluid is thinner than at rest.
TEST(Measure, SumsTheFiniteParticlesAndCountsTheRest) {
  const sim::FluidConstants fluid = sim::derive_fluid_constants(kSpacing, sim::SolverParams{});
  sim::ParticleSet set;
  set.append({0.5f, 0.5f, 0.05f}, {1.0f, 0.0f, 0.0f}, 0);
  set.append({0.6f, 0.5f, 0.05f}, {0.0f, 2.0f, 0.0f}, 1);
  set.append({2.9f, 0.5f, 0.05f}, {0.0f, 0.0f, 0.0f}, 2);  // beyond the tank's 2 m
  const float nan = std::numeric_limits<float>::quiet_NaN();
  set.append({nan, 0.5f, 0.05f}, {0.0f, 0.0f, 0.0f}, 3);
  const sim::FluidStatistics s = sim::measure(set, fluid, kTank);
  EXPECT_EQ(s.particles, 4u);
  EXPECT_EQ(s.non_finite, 1u);
  EXPECT_EQ(s.outside_tank, 1u);
  EXPECT_NEAR(s.kinetic_energy, 0.5 * fluid.particle_mass * (1.0 + 4.0), 1e-12);
  EXPECT_DOUBLE_EQ(s.max_speed, 2.0);
  EXPECT_NEAR(s.centre_of_mass.x, (0.5 + 0.6 + 2.9) / 3.0, 1e-6);
  EXPECT_NEAR(s.centre_of_mass.y, 0.5, 1e-6);
  EXPECT_EQ(s.max_density_error, 0.0);
  EXPECT_EQ(s.avg_density_error, 0.0);
}

TEST(SurgeFront, NothingAtTheWallIsNoFront) {
  EXPECT_EQ(sim::surge_front(floor_layer(0.5f, 0.6f), kSpacing, kTank), 0.0);
}

TEST(MartinMoyce, VariablesAndTheirTimeShift) {
  // n² = 2, a = 0.1 m: T = √2 · t · √(g/a).
  const FrontPoint p = to_martin_moyce(0.1, 0.25, 0.1, 9.81, std::sqrt(2.0));
  EXPECT_NEAR(p.T, std::sqrt(2.0) * 0.1 * std::sqrt(98.1), 1e-9);
  EXPECT_NEAR(p.Z, 2.5, 1e-12);
  // A front that passes Z = 1.44 at T = 1.0 is shifted by +0.19.
  const std::vector<FrontPoint> simulated = {{0.0, 1.0}, {0.5, 1.2}, {1.0, 1.44}, {1.5, 2.0}};
  EXPECT_NEAR(shift_as_martin_and_moyce(simulated), 0.19, 1e-9);
}

TEST(MartinMoyce, ComparisonIsTheMeanRelativeErrorAtTheExperimentsPoints) {
  const auto experiment = martin_moyce_n2_front();
  ASSERT_EQ(experiment.size(), 17u);
  // The experiment itself, as a simulation: no error.
  const std::vector<FrontPoint> same(experiment.begin(), experiment.end());
  EXPECT_NEAR(compare_fronts(same, experiment, 0.0, 4.44).mean_relative_error, 0.0, 1e-12);
  // Ten per cent ahead everywhere.
  std::vector<FrontPoint> ahead = same;
  for (FrontPoint& p : ahead) p.Z *= 1.1;
  const FrontComparison c = compare_fronts(ahead, experiment, 0.0, 4.44);
  EXPECT_EQ(c.points, 17u);
  EXPECT_NEAR(c.mean_relative_error, 0.1, 1e-9);
  // Points beyond t_max or outside the simulated span are not compared.
  EXPECT_EQ(compare_fronts(ahead, experiment, 0.0, 2.0).points, 7u);
  EXPECT_EQ(compare_fronts(ahead, experiment, 1.0, 4.44).points, 14u);  // from T = 1.41
}

TEST(SvgPlot, DrawsEverySeriesAndLabel) {
  Chart chart{"title <1>",
              "T",
              "Z",
              {{"experiment", "black", true, {0, 1, 2}, {1, 2, 3}},
               {"simulated", "red", false, {0, 1, 2}, {1, 2.5, 3.5}}}};
  const std::string svg = to_svg(chart);
  EXPECT_NE(svg.find("title &lt;1&gt;"), std::string::npos);
  EXPECT_NE(svg.find("<polyline"), std::string::npos);
  EXPECT_NE(svg.find(">simulated<"), std::string::npos);
  EXPECT_GT(std::count(svg.begin(), svg.end(), '\n'), 10);
}

}  // namespace
}  // namespace fluidcast::validation

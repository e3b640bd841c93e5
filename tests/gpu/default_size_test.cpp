// The default particle count: the ladder's decision on given costs, and the measurement on the
// device that runs the tests (lavapipe here and in CI).
#include "session/default_size.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "gpu_test_support.h"

namespace fluidcast::server {
namespace {

constexpr double kStepsPerSecond = 120.0;  // 240 substeps a second in motion

TEST(DefaultSizeTest, TakesTheLargestCountThatFitsItsShareAndProbesOnePast) {
  std::vector<std::uint32_t> probed;
  // 1 ms a substep per 4000 particles: 5000 take 30 % of the device, 10 000 take 60 %.
  const DefaultSize size = choose_default_particles(
      [&](std::uint32_t n) {
        probed.push_back(n);
        return n / 4000.0;
      },
      1u << 20, kStepsPerSecond, 0.5);
  EXPECT_EQ(size.particles, 5000u);
  EXPECT_DOUBLE_EQ(size.ms_per_substep, 1.25);
  EXPECT_NEAR(size.device_share, 0.3, 1e-12);
  EXPECT_EQ(probed, (std::vector<std::uint32_t>{1000, 2000, 5000, 10000}));
}

TEST(DefaultSizeTest, StopsAtTheSessionLimit) {
  std::vector<std::uint32_t> probed;
  const DefaultSize size = choose_default_particles(
      [&](std::uint32_t n) {
        probed.push_back(n);
        return 1e-6 * n;
      },
      3000, kStepsPerSecond, 0.5);
  EXPECT_EQ(size.particles, 3000u);
  EXPECT_EQ(probed, (std::vector<std::uint32_t>{1000, 2000, 3000}));
}

TEST(DefaultSizeTest, ClimbsToTheTopOfTheLadderOnAFastDevice) {
  const DefaultSize size =
      choose_default_particles([](std::uint32_t) { return 0.01; }, 16u << 20, kStepsPerSecond, 0.5);
  EXPECT_EQ(size.particles, kDefaultParticleLadder.back());
}

TEST(DefaultSizeTest, TheSmallestCountWhenNoneFits) {
  const DefaultSize size =
      choose_default_particles([](std::uint32_t) { return 50.0; }, 1u << 20, kStepsPerSecond, 0.5);
  EXPECT_EQ(size.particles, kDefaultParticleLadder.front());
  EXPECT_GT(size.device_share, 0.5);  // said as it is: the fluid will run in slow motion
}

class DefaultSizeMeasureTest : public testing::GpuTest {};

// Both solvers' measurements are real costs: positive, finite, and not absurd for a small fluid.
// (How they grow with the count is not asked: beside other tests on two cores, the CPU solver's
// threads wait for each other whatever the count — 19 ms at 1000 particles once in CI.)
TEST_F(DefaultSizeMeasureTest, MeasuresTheSolverThatSessionsUse) {
  for (const bool gpu_solver : {false, true}) {
    SCOPED_TRACE(gpu_solver ? "GPU solver" : "CPU solver");
    for (const std::uint32_t particles : {1000u, 5000u}) {
      const double ms = measure_ms_per_substep(context(), gpu_solver, particles);
      EXPECT_TRUE(std::isfinite(ms) && ms > 0.0 && ms < 10000.0) << ms << " ms at " << particles;
    }
  }
}

}  // namespace
}  // namespace fluidcast::server

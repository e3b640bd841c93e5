// The GPU counting sort against the CPU grid: the same cell for every particle and the same cell
// ranges, exactly. Within a cell the GPU order follows its atomics, so cells compare as sets.
#include "fluidcast/sim/gpu_neighbour_grid.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "fluidcast/gpu/transfer.h"
#include "gpu_test_support.h"

namespace fluidcast::sim::gpu_solver {
namespace {

using testing::GpuTest;

class GpuNeighbourGridTest : public GpuTest {
 protected:
  void expect_same_as_cpu(const Box& domain, float radius, const std::vector<glm::vec3>& points) {
    NeighbourGrid cpu(domain, radius);
    ForkJoinPool pool(2);
    cpu.build(pool, points);

    const auto n = static_cast<std::uint32_t>(points.size());
    GpuNeighbourGrid gpu_grid(context(), cpu.geometry(), n);
    std::vector<glm::vec4> key(points.size());
    std::transform(points.begin(), points.end(), key.begin(),
                   [](glm::vec3 p) { return glm::vec4(p, 0.0f); });
    const gpu::Buffer key_buffer(context(), key.size() * sizeof(glm::vec4),
                                 gpu::MemoryDomain::device);
    gpu::upload<glm::vec4>(context(), key_buffer, key);
    std::vector<GpuStepBatch::Pass> passes{
        {0, 0, [&](VkCommandBuffer commands) { gpu_grid.record_clear(commands); }}};
    gpu_grid.append_build(passes, key_buffer.address(), n, 0);
    // Recorded and submitted as a solver's step is.
    GpuStepBatch batch(context());
    GpuStepBatch::Receipt receipt;
    batch.queue(&gpu_grid, n, std::move(passes), receipt);
    batch.submit();
    ASSERT_TRUE(context().wait_for(receipt.serial));

    const auto cell_start =
        gpu::download<std::uint32_t>(context(), gpu_grid.cell_start(), cpu.cell_count() + 1);
    ASSERT_TRUE(std::equal(cell_start.begin(), cell_start.end(), cpu.cell_start().begin()))
        << "cell ranges differ";
    auto order = gpu::download<std::uint32_t>(context(), gpu_grid.order(), n);
    std::vector<std::uint32_t> expected(cpu.order().begin(), cpu.order().end());
    for (std::size_t c = 0; c < cpu.cell_count(); ++c) {
      std::sort(order.begin() + cell_start[c], order.begin() + cell_start[c + 1]);
    }
    // The CPU sort is stable: within a cell its order is already increasing.
    EXPECT_EQ(order, expected);
    const auto sorted_cell = gpu::download<std::uint32_t>(context(), gpu_grid.sorted_cell(), n);
    for (std::size_t c = 0; c < cpu.cell_count(); ++c) {
      for (std::uint32_t k = cell_start[c]; k < cell_start[c + 1]; ++k) {
        ASSERT_EQ(sorted_cell[k], c) << "slot " << k;
      }
    }
  }

  std::vector<glm::vec3> random_points(const Box& box, std::size_t n, unsigned seed) {
    std::mt19937 random(seed);
    std::uniform_real_distribution<float> x(box.min.x, box.max.x), y(box.min.y, box.max.y),
        z(box.min.z, box.max.z);
    std::vector<glm::vec3> points(n);
    for (auto& p : points) p = {x(random), y(random), z(random)};
    return points;
  }

  const Box box_{{0.0f, 0.0f, 0.0f}, {0.4f, 0.3f, 0.2f}};
  const float radius_ = 0.02f;
};

TEST_F(GpuNeighbourGridTest, NoParticles) { expect_same_as_cpu(box_, radius_, {}); }

TEST_F(GpuNeighbourGridTest, OneParticle) {
  expect_same_as_cpu(box_, radius_, {{0.1f, 0.1f, 0.1f}});
}

TEST_F(GpuNeighbourGridTest, WorkgroupSizeAndOneEitherSide) {
  const std::uint32_t g = GpuNeighbourGrid::kGroupSize;
  for (std::uint32_t n : {g - 1, g, g + 1, 2 * g + 1}) {
    SCOPED_TRACE(n);
    expect_same_as_cpu(box_, radius_, random_points(box_, n, n));
  }
}

TEST_F(GpuNeighbourGridTest, ManyRandomParticles) {
  expect_same_as_cpu(box_, radius_, random_points(box_, 20000, 7));
}

TEST_F(GpuNeighbourGridTest, PrefixSumBlockAndOneEitherSide) {
  // cells + 1 elements are scanned: make that one block, and one element either side.
  const float cell = radius_ / GridGeometry::kCellsPerRadius;
  for (std::uint32_t cells : {GpuNeighbourGrid::kScanBlock - 2, GpuNeighbourGrid::kScanBlock - 1,
                              GpuNeighbourGrid::kScanBlock}) {
    SCOPED_TRACE(cells);
    const Box line{{0, 0, 0},
                   {cell * (static_cast<float>(cells) - 0.5f), cell * 0.5f, cell * 0.5f}};
    ASSERT_EQ(GridGeometry(line, radius_).cell_count(), cells);
    expect_same_as_cpu(line, radius_, random_points(line, 3000, cells));
  }
}

// A tank of a 1M-particle fluid's size: hundreds of blocks, two levels.
TEST_F(GpuNeighbourGridTest, MillionsOfCellsInTwoLevels) {
  const Box big{{-1, -1, -1}, {0.3f, 0.3f, 0.3f}};  // 130³ = 2.2M cells of 1 cm
  const std::size_t cells = GridGeometry(big, radius_).cell_count();
  ASSERT_GT(cells, 1'000'000u);
  ASSERT_LT(cells + 1, std::size_t{GpuNeighbourGrid::kScanBlock} * GpuNeighbourGrid::kScanBlock);
  expect_same_as_cpu(big, radius_, random_points(big, 50000, 3));
}

// Past kScanBlock² elements the prefix sum takes a third level.
TEST_F(GpuNeighbourGridTest, ThreeLevelsOfPrefixSum) {
  const Box big{{-1.3f, -1.3f, -1.3f}, {1.3f, 1.3f, 1.3f}};  // 260³ = 17.6M cells of 1 cm
  ASSERT_GT(GridGeometry(big, radius_).cell_count() + 1,
            std::size_t{GpuNeighbourGrid::kScanBlock} * GpuNeighbourGrid::kScanBlock);
  expect_same_as_cpu(big, radius_, random_points(big, 50000, 4));
}

TEST_F(GpuNeighbourGridTest, AllParticlesInOneCell) {
  std::vector<glm::vec3> points(3000, glm::vec3(0.2f, 0.15f, 0.1f));
  expect_same_as_cpu(box_, radius_, points);
}

TEST_F(GpuNeighbourGridTest, CellBordersOutsideTheDomainAndNonFinite) {
  std::vector<glm::vec3> points;
  const float cell = radius_ / GridGeometry::kCellsPerRadius;
  for (int k = 0; k <= 40; ++k) points.push_back({k * cell, k * 0.5f * cell, 0.0f});
  const float inf = std::numeric_limits<float>::infinity();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  points.insert(points.end(), {{-5, -5, -5},
                               {5, 5, 5},
                               {inf, -inf, 0},
                               {nan, 0.1f, 0.1f},
                               {0.4f, 0.3f, 0.2f},
                               {0, 0, 0},
                               {-0.0f, 0.3f, 1e30f}});
  expect_same_as_cpu(box_, radius_, points);
}

}  // namespace
}  // namespace fluidcast::sim::gpu_solver

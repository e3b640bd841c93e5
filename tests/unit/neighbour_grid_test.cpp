// The counting-sort grid and the neighbour lists built from it, against brute force.
#include "fluidcast/sim/neighbour_grid.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>
#include <set>
#include <string>

#include "fluidcast/sim/fluid_constants.h"
#include "fluidcast/sim/kernels.h"
#include "fluidcast/sim/neighbour_list.h"
#include "fluidcast/sim/solver_params.h"

namespace fluidcast::sim {
namespace {

const Box kDomain{{0, 0, 0}, {1.0f, 0.6f, 0.4f}};
constexpr float kRadius = 0.1f;

using Pairs = std::set<std::pair<std::uint32_t, std::uint32_t>>;

// Pairs (by original index) within the radius, every pair in both orders.
Pairs brute_force(const std::vector<glm::vec3>& p, float radius) {
  Pairs pairs;
  for (std::uint32_t i = 0; i < p.size(); ++i) {
    for (std::uint32_t j = 0; j < p.size(); ++j) {
      const glm::vec3 d = p[i] - p[j];
      if (i != j && glm::dot(d, d) < radius * radius) pairs.insert({i, j});
    }
  }
  return pairs;
}

constexpr std::uint32_t kUnlimited = std::numeric_limits<std::uint32_t>::max();

// Points sorted by the grid's cells, as a solver sorts them, and their lists.
struct Listed {
  std::vector<glm::vec3> sorted;
  std::vector<std::uint32_t> order;  // as NeighbourGrid::order()
  NeighbourList list;
};

Listed list_through_grid(const std::vector<glm::vec3>& points, float radius, unsigned threads,
                         std::uint32_t max_candidates, std::uint32_t max_neighbours) {
  ForkJoinPool pool(threads);
  NeighbourGrid grid(kDomain, radius);
  grid.build(pool, points);
  Listed listed;
  listed.order.assign(grid.order().begin(), grid.order().end());
  listed.sorted = points;
  std::vector<glm::vec3> scratch;
  apply_order(pool, grid.order(), listed.sorted, scratch);
  listed.list.build(pool, grid, listed.sorted, radius, max_candidates, max_neighbours);
  return listed;
}

Pairs through_grid(const std::vector<glm::vec3>& original, float radius, unsigned threads) {
  const Listed listed = list_through_grid(original, radius, threads, kUnlimited, kUnlimited);
  Pairs pairs;
  for (std::size_t k = 0; k < listed.sorted.size(); ++k) {
    const auto neighbours = listed.list.of(k);
    EXPECT_TRUE(std::is_sorted(neighbours.begin(), neighbours.end()));
    for (std::uint32_t j : neighbours) pairs.insert({listed.order[k], listed.order[j]});
  }
  return pairs;
}

std::vector<glm::vec3> random_points(std::size_t n, const Box& box, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::vector<glm::vec3> p(n);
  for (auto& x : p) x = box.min + glm::vec3(u(rng), u(rng), u(rng)) * box.size();
  return p;
}

void expect_matches_brute_force(const std::vector<glm::vec3>& p) {
  const Pairs expected = brute_force(p, kRadius);
  for (unsigned threads : {1u, 2u, 3u}) {
    EXPECT_EQ(through_grid(p, kRadius, threads), expected) << threads << " threads";
  }
}

// Every particle at one point: without a cap each would examine all n; with it, at most the cap,
// and the lists take memory linear in n.
TEST(NeighbourList, AClumpExaminesAtMostTheCapPerParticle) {
  const std::vector<glm::vec3> clump(3000, glm::vec3(0.5f, 0.3f, 0.2f));
  constexpr std::uint32_t cap = 200;
  const Listed listed = list_through_grid(clump, kRadius, 2, cap, kUnlimited);
  const NeighbourList& list = listed.list;
  std::size_t entries = 0;
  for (std::size_t k = 0; k < clump.size(); ++k) {
    ASSERT_LE(list.of(k).size(), cap);
    entries += list.of(k).size();
  }
  EXPECT_LE(entries, clump.size() * cap);
  EXPECT_GE(entries, clump.size() * (cap - 1));  // the cap, not fewer
}

// The same clump with room for fewer neighbours than it examines: each list holds exactly its
// first max_neighbours, in index order, as the GPU solver's fixed-length lists do.
TEST(NeighbourList, AClumpListsAtMostTheNeighbourCapPerParticle) {
  const std::vector<glm::vec3> clump(3000, glm::vec3(0.5f, 0.3f, 0.2f));
  constexpr std::uint32_t most = 50;
  const Listed listed = list_through_grid(clump, kRadius, 2, 200, most);
  const NeighbourList& list = listed.list;
  for (std::size_t k = 0; k < clump.size(); ++k) {
    const auto neighbours = list.of(k);
    ASSERT_EQ(neighbours.size(), most) << k;
    EXPECT_EQ(neighbours.front(), k == 0 ? 1u : 0u);
    EXPECT_TRUE(std::is_sorted(neighbours.begin(), neighbours.end()));
  }
  constexpr std::uint32_t padded = (most + lanes::kWidth - 1) / lanes::kWidth * lanes::kWidth;
  EXPECT_EQ(list.pair_count(), clump.size() * padded);  // each list padded to whole blocks
}

// Loops that take a block of neighbours at a time read each list padded to whole blocks, with the
// particle's own index in the padding, and keep per-pair values at first_pair: every list's
// blocks start on a block and no two lists' blocks overlap.
TEST(NeighbourList, ListsArePaddedToWholeBlocksOfTheirOwnIndex) {
  const Listed listed =
      list_through_grid(random_points(2000, kDomain, 7), kRadius, 2, kUnlimited, kUnlimited);
  const NeighbourList& list = listed.list;
  std::size_t next_pair = 0;
  for (std::size_t k = 0; k < list.size(); ++k) {
    const auto listed_k = list.of(k);
    const auto blocks = list.blocks_of(k);
    ASSERT_EQ(blocks.size() % lanes::kWidth, 0u) << k;
    ASSERT_LT(blocks.size() - listed_k.size(), lanes::kWidth) << k;
    ASSERT_TRUE(std::equal(listed_k.begin(), listed_k.end(), blocks.begin())) << k;
    for (std::size_t e = listed_k.size(); e < blocks.size(); ++e) ASSERT_EQ(blocks[e], k) << k;
    ASSERT_EQ(list.first_pair(k) % lanes::kWidth, 0u) << k;
    ASSERT_GE(list.first_pair(k), next_pair) << k;   // in order and apart: the pool's chunks keep
    next_pair = list.first_pair(k) + blocks.size();  // particles in order
  }
  EXPECT_LE(next_pair, list.pair_count());
}

// The cap counts across a particle's rows of cells: 30 particles in a lower row, 3000 in the row
// above within the radius. Every list holds 50: a lower particle's 29 others and 21 from above,
// an upper particle's 30 from below first and then 20 of its own.
TEST(NeighbourList, TheNeighbourCapCountsAcrossRowsOfCells) {
  std::vector<glm::vec3> points(30, glm::vec3(0.5f, 0.3f, 0.2f));
  points.resize(3030, glm::vec3(0.5f, 0.3f + 0.6f * kRadius, 0.2f));
  constexpr std::uint32_t most = 50;
  const Listed listed = list_through_grid(points, kRadius, 2, kUnlimited, most);
  const std::vector<glm::vec3>& sorted = listed.sorted;
  const NeighbourList& list = listed.list;
  const auto lower = [&](std::uint32_t j) { return sorted[j].y < 0.3f + 0.3f * kRadius; };
  for (std::uint32_t k = 0; k < sorted.size(); ++k) {
    const auto neighbours = list.of(k);
    ASSERT_EQ(neighbours.size(), most) << k;
    const auto below = std::count_if(neighbours.begin(), neighbours.end(), lower);
    EXPECT_EQ(below, lower(k) ? 29 : 30) << k;
  }
}

TEST(FluidConstants, TheCandidateCapIsFourTimesAFluidAtRest) {
  SolverParams params;
  params.kernel_ratio = 2.0f;
  // 5 cells of h/2 a side: 2.5 h = 5 spacings, 125 lattice sites.
  EXPECT_EQ(derive_fluid_constants(0.01f, params).max_candidates, 500u);
}

// A cubic lattice of fluid particles, its spacing 0.01 m, at a kernel ratio.
struct Lattice {
  static constexpr float kSpacing = 0.01f;
  explicit Lattice(float ratio)
      : fluid(derive_fluid_constants(kSpacing,
                                     [ratio] {
                                       SolverParams params;
                                       params.kernel_ratio = ratio;
                                       return params;
                                     }())),
        kernels(fluid.kernel_radius) {}
  // What its sites from `lowest` to `highest` (lattice steps, inclusive) add to the density at
  // `site`, as a share of ρ0.
  double reads_at(glm::ivec3 site, glm::ivec3 lowest, glm::ivec3 highest) const {
    double sum = 0.0;
    for (int k = lowest.z; k <= highest.z; ++k)
      for (int j = lowest.y; j <= highest.y; ++j)
        for (int i = lowest.x; i <= highest.x; ++i) {
          const glm::vec3 r = glm::vec3(glm::ivec3(i, j, k) - site) * kSpacing;
          sum += kernels.poly6(glm::dot(r, r));
        }
    return sum * fluid.particle_mass / fluid.rest_density;
  }
  FluidConstants fluid;
  Kernels kernels;
};

constexpr float kKernelRatios[] = {1.5f, 2.0f, 3.0f, 4.0f};

// The walls' fluid begins where a cubic lattice's first layer, half a spacing from the wall,
// reads ρ0 (particles and wall together), as the bulk does, at every kernel ratio.
TEST(FluidConstants, ALatticesLayerAtAWallSumsToRestDensity) {
  for (const float ratio : kKernelRatios) {
    const Lattice lattice(ratio);
    const FluidConstants& fluid = lattice.fluid;
    // The site half a spacing above the wall, the plane y = 0.
    const double particles = lattice.reads_at({0, 0, 0}, {-6, 0, -6}, {6, 6, 6});
    const double wall = lattice.kernels.wall_volume(0.5f * Lattice::kSpacing + fluid.wall_offset);
    EXPECT_NEAR(particles + wall, 1.0, 1e-4) << "kernel ratio " << ratio;
    EXPECT_GT(fluid.wall_offset, 0.0f) << "kernel ratio " << ratio;
  }
}

// Where walls meet, their half-spaces overlap (Kernels::walls): a cubic lattice filling a tank's
// edge or corner reads ρ0 at its sites there to within what the lattice itself leaves, which is
// up to 1.5 % over at a kernel ratio of 3 (its second layer at a single wall reads 0.7 % over
// there; at h = 2d, 0.14 %); at h = 2d the edge's first site reads 0.6 % under and the corner's
// 1.4 % under. With the half-spaces summed, they read 3.0 and 8.8 % over at h = 2d, 8.5 and 23 %
// at a ratio of 3, 12 and 32 % at 4.
TEST(FluidConstants, ALatticesEdgesAndCornersReadRestDensity) {
  for (const float ratio : kKernelRatios) {
    const Lattice lattice(ratio);
    const FluidConstants& fluid = lattice.fluid;
    const int reach = static_cast<int>(std::ceil(ratio)) + 1;  // lattice steps within h, and one
    const float far = 1.0f;                                    // m: no wall there
    for (const int walled : {2, 3}) {  // the axes with a wall at 0: x, y (and z)
      // Sites within h of every wall of theirs.
      for (int a = 0; (a + 0.5f) * Lattice::kSpacing < fluid.kernel_radius; ++a)
        for (int b = 0; b <= a; ++b)
          for (int c = 0; c <= (walled == 3 ? b : 0); ++c) {
            const glm::ivec3 site(a, b, c);
            const double particles =
                lattice.reads_at(site, {0, 0, walled == 3 ? 0 : -reach}, site + glm::ivec3(reach));
            glm::vec3 near = (glm::vec3(site) + 0.5f) * Lattice::kSpacing + fluid.wall_offset;
            if (walled == 2) near.z = far;
            const double reads = particles + lattice.kernels.walls(near, glm::vec3(far)).volume;
            const std::string where = "kernel ratio " + std::to_string(ratio) + ", site (" +
                                      std::to_string(a) + ", " + std::to_string(b) + ", " +
                                      std::to_string(c) + ") of " + std::to_string(walled) +
                                      " walls";
            EXPECT_LT(reads, 1.02) << where;
            EXPECT_GT(reads, 0.97) << where;
          }
    }
  }
}

TEST(FluidConstants, TheNeighbourCapIsTwiceAFluidAtRest) {
  SolverParams params;
  params.kernel_ratio = 2.0f;
  // A sphere of radius h = 2 spacings holds 4/3 π 8 = 33.5 spacings' cubes.
  EXPECT_EQ(derive_fluid_constants(0.01f, params).max_neighbours, 68u);
}

TEST(NeighbourGrid, EmptySet) {
  expect_matches_brute_force({});
  NeighbourGrid grid(kDomain, kRadius);
  ForkJoinPool pool(2);
  grid.build(pool, std::vector<glm::vec3>{});
  EXPECT_TRUE(grid.order().empty());
  EXPECT_EQ(grid.cell_start().back(), 0u);
}

TEST(NeighbourGrid, OneParticle) { expect_matches_brute_force({{0.5f, 0.3f, 0.2f}}); }

TEST(NeighbourGrid, RandomSetsMatchBruteForce) {
  for (unsigned seed = 1; seed <= 5; ++seed) {
    expect_matches_brute_force(random_points(300 * seed, kDomain, seed));
  }
}

TEST(NeighbourGrid, AllParticlesInOneCell) {
  expect_matches_brute_force(
      random_points(700, Box{{0.31f, 0.31f, 0.11f}, {0.39f, 0.39f, 0.19f}}, 7));
}

TEST(NeighbourGrid, ParticlesExactlyOnCellBorders) {
  std::vector<glm::vec3> p;
  for (int i = 0; i <= 10; ++i)
    for (int j = 0; j <= 6; ++j)
      for (int k = 0; k <= 4; ++k) p.push_back(glm::vec3(i, j, k) * kRadius);
  // Spacing equal to the radius: only the exact-distance pairs sit on the boundary, and the
  // half-spacing copies make many pairs just inside it.
  const std::size_t n = p.size();
  for (std::size_t i = 0; i < n; ++i) p.push_back(p[i] + glm::vec3(0.5f * kRadius));
  expect_matches_brute_force(p);
}

TEST(NeighbourGrid, PositionsOutsideTheDomainLandInBorderCells) {
  std::vector<glm::vec3> p = random_points(200, kDomain, 11);
  p.push_back({-5.0f, 0.3f, 0.2f});
  p.push_back({0.5f, 99.0f, 0.2f});
  p.push_back({1e30f, -1e30f, 0.2f});
  expect_matches_brute_force(p);
}

TEST(NeighbourGrid, OrderIsAStablePermutationSortedByCell) {
  const auto p = random_points(2000, kDomain, 3);
  NeighbourGrid grid(kDomain, kRadius);
  ForkJoinPool pool(3);  // cells are found in parallel; the order must not depend on it
  grid.build(pool, p);
  const auto order = grid.order();
  std::vector<std::uint32_t> sorted(order.begin(), order.end());
  std::sort(sorted.begin(), sorted.end());
  std::vector<std::uint32_t> identity(p.size());
  std::iota(identity.begin(), identity.end(), 0u);
  EXPECT_EQ(sorted, identity);
  for (std::size_t k = 1; k < order.size(); ++k) {
    const auto a = grid.cell_index(grid.cell_coords(p[order[k - 1]]));
    const auto b = grid.cell_index(grid.cell_coords(p[order[k]]));
    ASSERT_TRUE(a < b || (a == b && order[k - 1] < order[k])) << "slot " << k;
  }
  const auto start = grid.cell_start();
  EXPECT_EQ(start.front(), 0u);
  EXPECT_EQ(start.back(), p.size());
  for (std::size_t c = 0; c < grid.cell_count(); ++c) {
    for (auto k = start[c]; k < start[c + 1]; ++k) {
      ASSERT_EQ(grid.cell_index(grid.cell_coords(p[order[k]])), c);
    }
  }
}

TEST(NeighbourGrid, RefusesBadCellSizes) {
  EXPECT_THROW(NeighbourGrid(kDomain, 0.0f), std::invalid_argument);
  EXPECT_THROW(NeighbourGrid(kDomain, -1.0f), std::invalid_argument);
  EXPECT_THROW(NeighbourGrid(kDomain, std::nanf("")), std::invalid_argument);
  EXPECT_THROW(NeighbourGrid(Box{{0, 0, 0}, {100, 100, 100}}, 1e-4f), std::invalid_argument);
}

}  // namespace
}  // namespace fluidcast::sim

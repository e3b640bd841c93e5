// The generated Marching Cubes table: every case's triangles sit on the edges where the sign
// changes and use all of them; and on a random field the surface of many cells is closed and
// consistently oriented (every triangle edge met once in each direction), ambiguous faces included.
#include "marching_cubes_tables.h"

#include <gtest/gtest.h>

#include <map>
#include <random>
#include <set>

namespace fluidcast::render {
namespace {

TEST(MarchingCubesTables, TrianglesUseExactlyTheCrossedEdges) {
  const auto& tables = MarchingCubesTables::get();
  EXPECT_EQ(tables.triangle_count[0], 0);
  EXPECT_EQ(tables.triangle_count[255], 0);
  int most = 0;
  for (int pattern = 0; pattern < 256; ++pattern) {
    std::set<int> crossed, used;
    for (int e = 0; e < 12; ++e) {
      const auto [a, b] = edge_corners(e);
      if (((pattern >> a) & 1) != ((pattern >> b) & 1)) crossed.insert(e);
    }
    const int count = tables.triangle_count[pattern];
    for (int k = 0; k < 3 * count; ++k) used.insert(tables.triangles[pattern][k]);
    EXPECT_EQ(tables.triangles[pattern][3 * count], -1) << pattern;
    EXPECT_EQ(used, crossed) << "case " << pattern;
    most = std::max(most, count);
  }
  EXPECT_LE(most, MarchingCubesTables::kMaxTriangles);
}

TEST(MarchingCubesTables, ARandomFieldGivesAClosedOrientedSurface) {
  constexpr int n = 9;  // nodes per side; the outer layer is kept outside so the surface closes
  std::mt19937 random(11);
  std::uniform_real_distribution<float> value(0.0f, 1.0f);
  std::vector<float> field(n * n * n, 0.0f);
  const auto node = [&](glm::ivec3 p) { return p.x + n * (p.y + n * p.z); };
  for (int z = 1; z + 1 < n; ++z)
    for (int y = 1; y + 1 < n; ++y)
      for (int x = 1; x + 1 < n; ++x) field[node({x, y, z})] = value(random);
  const float threshold = 0.5f;
  // A surface point is named by the two nodes of its grid edge, smaller first.
  std::map<std::pair<std::pair<int, int>, std::pair<int, int>>, int> directed;
  const auto& tables = MarchingCubesTables::get();
  int triangles = 0;
  for (int z = 0; z + 1 < n; ++z) {
    for (int y = 0; y + 1 < n; ++y) {
      for (int x = 0; x + 1 < n; ++x) {
        int pattern = 0;
        for (int c = 0; c < 8; ++c) {
          if (field[node(glm::ivec3(x, y, z) + corner_offset(c))] > threshold) pattern |= 1 << c;
        }
        const auto point = [&](int edge) {
          const auto [a, b] = edge_corners(edge);
          const int na = node(glm::ivec3(x, y, z) + corner_offset(a));
          const int nb = node(glm::ivec3(x, y, z) + corner_offset(b));
          return std::pair{std::min(na, nb), std::max(na, nb)};
        };
        for (int t = 0; t < tables.triangle_count[pattern]; ++t) {
          ++triangles;
          for (int j = 0; j < 3; ++j) {
            const auto from = point(tables.triangles[pattern][3 * t + j]);
            const auto to = point(tables.triangles[pattern][3 * t + (j + 1) % 3]);
            ++directed[{from, to}];
          }
        }
      }
    }
  }
  ASSERT_GT(triangles, 100);
  for (const auto& [edge, count] : directed) {
    EXPECT_EQ(count, 1) << "a directed edge used twice: orientation is inconsistent";
    const auto reverse = directed.find({edge.second, edge.first});
    EXPECT_TRUE(reverse != directed.end() && reverse->second == 1) << "an open edge";
  }
}

}  // namespace
}  // namespace fluidcast::render

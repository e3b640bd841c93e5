#include "marching_cubes_tables.h"

#include <map>
#include <stdexcept>
#include <vector>

namespace fluidcast::render {
namespace {

constexpr int kCorners[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                                {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
constexpr int kEdges[12][2] = {{0, 1}, {1, 2}, {2, 3}, {3, 0}, {4, 5}, {5, 6},
                               {6, 7}, {7, 4}, {0, 4}, {1, 5}, {2, 6}, {3, 7}};
// Each face's corners, counter-clockwise seen from outside the cell.
constexpr int kFaces[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4},
                              {2, 3, 7, 6}, {0, 4, 7, 3}, {1, 2, 6, 5}};

int edge_between(int a, int b) {
  for (int e = 0; e < 12; ++e) {
    if ((kEdges[e][0] == a && kEdges[e][1] == b) || (kEdges[e][0] == b && kEdges[e][1] == a)) {
      return e;
    }
  }
  throw std::logic_error("marching cubes: corners " + std::to_string(a) + " and " +
                         std::to_string(b) + " share no edge");
}

MarchingCubesTables build() {
  MarchingCubesTables tables;
  for (int pattern = 0; pattern < 256; ++pattern) {
    const auto inside = [&](int corner) { return (pattern >> corner) & 1; };
    // On each face, for each run of inside corners (going counter-clockwise), a segment from the
    // edge where the run ends to the edge where it begins.
    std::map<int, int> next;  // surface point (edge) → the next one around its loop
    for (const auto& face : kFaces) {
      for (int k = 0; k < 4; ++k) {
        const int corner = face[k], following = face[(k + 1) % 4];
        if (inside(corner) && !inside(following)) {  // a run ends at corner
          const int exit = edge_between(corner, following);
          int start = k;
          while (inside(face[(start + 3) % 4]) && (start + 3) % 4 != k) start = (start + 3) % 4;
          const int entry = edge_between(face[(start + 3) % 4], face[start]);
          if (!next.emplace(exit, entry).second) {
            throw std::logic_error("marching cubes: a surface point starts two segments");
          }
        }
      }
    }
    // Follow the loops and cut each into a fan of triangles.
    int written = 0;
    while (!next.empty()) {
      std::vector<int> loop;
      for (int point = next.begin()->first; next.count(point) != 0;) {
        loop.push_back(point);
        const int following = next.at(point);
        next.erase(point);
        point = following;
      }
      for (std::size_t k = 1; k + 1 < loop.size(); ++k) {
        if (written == MarchingCubesTables::kMaxTriangles) {
          throw std::logic_error("marching cubes: more triangles than a cell can have");
        }
        auto& row = tables.triangles[pattern];
        row[3 * written] = static_cast<std::int8_t>(loop[0]);
        row[3 * written + 1] = static_cast<std::int8_t>(loop[k]);
        row[3 * written + 2] = static_cast<std::int8_t>(loop[k + 1]);
        ++written;
      }
    }
    tables.triangles[pattern][3 * written] = -1;
    tables.triangle_count[pattern] = static_cast<std::uint8_t>(written);
  }
  return tables;
}

}  // namespace

const MarchingCubesTables& MarchingCubesTables::get() {
  static const MarchingCubesTables tables = build();
  return tables;
}

glm::ivec3 corner_offset(int corner) {
  return {kCorners[corner][0], kCorners[corner][1], kCorners[corner][2]};
}

std::array<int, 2> edge_corners(int edge) { return {kEdges[edge][0], kEdges[edge][1]}; }

}  // namespace fluidcast::render

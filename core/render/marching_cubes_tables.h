// The Marching Cubes case table (Lorensen & Cline 1987), built at start-up rather than typed in:
// for each of the 256 inside/outside patterns of a cell's corners, the triangles, as triples of
// cell edges whose surface points they join. On every face, the crossings are joined around each
// run of inside corners, which resolves the ambiguous faces the same way from both sides, so
// neighbouring cells meet without cracks and the surface is closed.
// Bit i of a case is corner i (see corner_offset): set where the field is above the threshold.
#pragma once

#include <array>
#include <cstdint>
#include <glm/glm.hpp>

namespace fluidcast::render {

struct MarchingCubesTables {
  static constexpr int kMaxTriangles = 5;  // per cell, for the standard corner numbering

  // triangles[case][3 k + j]: edge of vertex j of triangle k; -1 after the last.
  std::array<std::array<std::int8_t, 3 * kMaxTriangles + 1>, 256> triangles{};
  std::array<std::uint8_t, 256> triangle_count{};

  static const MarchingCubesTables& get();
};

// Corner c of the unit cell: 0 (0,0,0), 1 (1,0,0), 2 (1,1,0), 3 (0,1,0), 4..7 the same at z = 1.
glm::ivec3 corner_offset(int corner);
// The two corners of edge e: 0–3 around z = 0, 4–7 around z = 1, 8–11 along z.
std::array<int, 2> edge_corners(int edge);

}  // namespace fluidcast::render

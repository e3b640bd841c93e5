#version 460
#extension GL_GOOGLE_include_directive : require
// Counting sort, step 4: each particle's sorted slot records the particle and its cell
// (grid_scatter).
#include "common/core.glsl"
#include "common/grid.glsl"
#include "common/grid_pass.glsl"

void main() {
  const uint i = invocation();
  if (i >= pass.particle_count) return;
  grid_scatter(i, pass.cell_of, pass.rank, pass.cell_start, pass.order, pass.sorted_cell);
}

#version 460
#extension GL_GOOGLE_include_directive : require
// Counting sort, step 1: each particle's cell, and its rank in the cell (grid_count).
#include "common/core.glsl"
#include "common/grid.glsl"
#include "common/grid_pass.glsl"

void main() {
  const uint i = invocation();
  if (i >= pass.particle_count) return;
  grid_count(i, pass.key.v[i].xyz, pass.origin, pass.dims.xyz, pass.cell_of, pass.rank,
             pass.cell_start);
}

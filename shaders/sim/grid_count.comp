#version 460
#extension GL_GOOGLE_include_directive : require
// Counting sort, step 1: each particle's cell, and its rank in the cell from an atomic count.
#include "common/core.glsl"
#include "common/grid.glsl"
#include "common/grid_pass.glsl"

void main() {
  const uint i = invocation();
  if (i >= pass.particle_count) return;
  const ivec3 c = grid_cell_coords(pass.key.v[i].xyz, pass.origin.xyz, pass.origin.w, pass.dims.xyz);
  const uint cell = grid_cell_index(c, pass.dims.xyz);
  pass.cell_of.v[i] = cell;
  pass.rank.v[i] = atomicAdd(pass.cell_start.v[cell], 1u);
}

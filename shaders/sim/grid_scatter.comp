#version 460
#extension GL_GOOGLE_include_directive : require
// Counting sort, step 4: each particle's sorted slot is its cell's start plus its rank; the slot
// records the particle and its cell.
#include "common/core.glsl"
#include "common/grid.glsl"
#include "common/grid_pass.glsl"

void main() {
  const uint i = invocation();
  if (i >= pass.particle_count) return;
  const uint cell = pass.cell_of.v[i];
  const uint slot = pass.cell_start.v[cell] + pass.rank.v[i];
  pass.order.v[slot] = i;
  pass.sorted_cell.v[slot] = cell;
}

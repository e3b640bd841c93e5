#version 460
#extension GL_GOOGLE_include_directive : require
// Counting sort, step 4: each particle's sorted slot is its cell's start plus its rank.
#include "common/core.glsl"
#include "common/grid.glsl"
#include "common/grid_pass.glsl"

void main() {
  const uint i = invocation();
  if (i >= pass.particle_count) return;
  pass.order.v[pass.cell_start.v[pass.cell_of.v[i]] + pass.rank.v[i]] = i;
}

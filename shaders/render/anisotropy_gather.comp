#version 460
#extension GL_GOOGLE_include_directive : require
// SSFR's anisotropy, first: the particles' positions in the grid's sorted order, so that the
// neighbour loops read each row of cells from one stretch of memory.
#include "common/core.glsl"
#include "common/anisotropy_pass.glsl"

void main() {
  const uint k = invocation();
  if (k >= a.particle_count) return;
  a.sorted_position.v[k] = a.position.v[a.order.v[k]];
}

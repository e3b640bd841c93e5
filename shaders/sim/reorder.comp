#version 460
#extension GL_GOOGLE_include_directive : require
// Gathers every particle attribute into the sorted order the grid just built: the one place
// where particles are reordered.
#include "common/core.glsl"
#include "common/sim_params.glsl"

void main() {
  const uint k = invocation();
  if (k >= P.particle_count) return;
  const uint i = P.order.v[k];
  P.sorted_position.v[k] = P.position.v[i];
  P.sorted_velocity.v[k] = P.velocity.v[i];
  P.sorted_id.v[k] = P.id.v[i];
  if (P.solver == SOLVER_PBF) P.iterate.v[k] = P.predicted.v[i];
}

#version 460
#extension GL_GOOGLE_include_directive : require
// PBF, in state order: gravity into the velocity, slowed to the substep's travel if faster
// (PbfSubsteps::speed_limit), and the predicted position, constrained; then the prediction
// counted into its cell (grid_count), the first step of the grid build that sorts by it.
#include "common/core.glsl"
#include "common/sim_params.glsl"
#include "common/sim_kernels.glsl"

void main() {
  load_constants();
  const uint i = invocation();
  if (i >= P.particle_count) return;
  vec3 v = P.velocity.v[i].xyz + pass.dt * P.gravity.xyz;
  const float limit = P.substep_travel / pass.dt;
  const float speed2 = dot(v, v);
  if (speed2 > limit * limit) v *= limit * inversesqrt(speed2);
  P.velocity.v[i] = vec4(v, 0.0);
  const vec3 predicted = constrain(P.position.v[i].xyz + pass.dt * v, v, false);
  P.predicted.v[i] = vec4(predicted, 0.0);
  Uints cell_of = P.cell_of, rank = P.rank;  // a block member cannot be passed as a reference
  grid_count(i, predicted, P.grid_origin, K_grid_dims, cell_of, rank, K_cell_start);
}

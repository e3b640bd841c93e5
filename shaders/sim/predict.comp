#version 460
#extension GL_GOOGLE_include_directive : require
// PBF, in state order: gravity into the velocity, slowed to the substep's travel if faster
// (PbfSubsteps::speed_limit), and the predicted position, constrained.
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
  P.predicted.v[i] = vec4(constrain(P.position.v[i].xyz + pass.dt * v, v, false), 0.0);
}

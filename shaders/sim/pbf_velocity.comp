#version 460
#extension GL_GOOGLE_include_directive : require
// PBF: the velocity from the corrected position, v = (x* − x) / Δt, in sorted order.
#include "common/core.glsl"
#include "common/sim_params.glsl"

void main() {
  const uint k = invocation();
  if (k >= P.particle_count) return;
  Vec4s x = pass.parity == 0u ? P.iterate0 : P.iterate1;
  P.sorted_velocity.v[k] = vec4((x.v[k].xyz - P.sorted_position.v[k].xyz) / pass.dt, 0.0);
}

#version 460
#extension GL_GOOGLE_include_directive : require
// PBF: ω_i = Σ_j V (v_j − v_i) × ∇_j W_ij, the curl of the velocity; |ω| in w.
#include "common/core.glsl"
#include "common/sim_params.glsl"
#include "common/sim_kernels.glsl"

void main() {
  load_constants();
  const uint k = invocation();
  if (k >= P.particle_count) return;
  Vec4s x = pass.parity == 0u ? P.iterate0 : P.iterate1;
  const vec3 p = x.v[k].xyz;
  Vec4s velocity = P.sorted_velocity;
  const vec3 v = velocity.v[k].xyz;
  vec3 omega = vec3(0.0);
  const ivec3 cell = sorted_cell(k);
  FOR_EACH_CANDIDATE(cell, j) {
    const vec3 r = p - x.v[j].xyz;
    const float r2 = dot(r, r);
    if (!(r2 < K_h2) || j == k) continue;
    omega += cross(velocity.v[j].xyz - v, -spiky_gradient(r, r2));
  }
  omega *= P.rest_volume;
  P.vorticity.v[k] = vec4(omega, length(omega));
}

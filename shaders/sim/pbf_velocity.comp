#version 460
#extension GL_GOOGLE_include_directive : require
// PBF, in sorted order: the velocity from the corrected position, v = (x* − x) / Δt, and with
// vorticity confinement on, ω_i = Σ_j V (v_j − v_i) × ∇_j W_ij, the curl of the velocity (|ω| in
// w). One pass: the neighbours' velocities are formed from their positions as they are read,
// which costs the loop no more reads than reading stored velocities would, and saves a pass and
// a barrier.
#include "common/core.glsl"
#include "common/sim_params.glsl"
#include "common/sim_kernels.glsl"

void main() {
  load_constants();
  const uint k = invocation();
  if (k >= P.particle_count) return;
  Vec4s x = pass.parity == 0u ? P.iterate0 : P.iterate1;
  Vec4s start = P.sorted_position;
  const float inv_dt = 1.0 / pass.dt;
  const vec3 p = x.v[k].xyz;
  const vec3 v = (p - start.v[k].xyz) * inv_dt;
  P.sorted_velocity.v[k] = vec4(v, 0.0);
  if (P.vorticity_epsilon <= 0.0) return;
  vec3 omega = vec3(0.0);
  const ivec3 cell = sorted_cell(k);
  FOR_EACH_CANDIDATE(cell, j) {
    const vec3 p_j = x.v[j].xyz;
    const vec3 r = p - p_j;
    const float r2 = dot(r, r);
    if (!(r2 < K_h2) || j == k) continue;
    const vec3 v_j = (p_j - start.v[j].xyz) * inv_dt;
    omega += cross(v_j - v, -spiky_gradient(r, r2));
  }
  omega *= P.rest_volume;
  P.vorticity.v[k] = vec4(omega, length(omega));
}

#version 460
#extension GL_GOOGLE_include_directive : require
// PBF, in sorted order, with vorticity confinement on: ω_i = Σ_j V (v_j − v_i) × ∇_j W_ij, the
// curl of the velocity (|ω| in w); as PbfSolver::sum_over_neighbours.
#include "common/core.glsl"
#include "common/sim_params.glsl"
#include "common/sim_kernels.glsl"

void main() {
  load_constants();
  const uint k = invocation();
  if (k >= P.particle_count) return;
  Vec4s x = P.iterate;
  Vec4s velocities = P.sorted_velocity;
  const vec3 p = x.v[k].xyz;
  const vec3 v = velocities.v[k].xyz;
  vec3 omega = vec3(0.0);
  for (uint e = 0u, count = neighbour_count(k); e < count; ++e) {
    const uint j = neighbour(k, e);
    const vec3 r = p - x.v[j].xyz;
    const float r2 = dot(r, r);
    if (!(r2 < K_h2)) continue;
    omega += cross(velocities.v[j].xyz - v, -spiky_gradient(r, r2));
  }
  omega *= P.rest_volume;
  P.vorticity.v[k] = vec4(omega, length(omega));
}

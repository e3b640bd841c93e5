#version 460
#extension GL_GOOGLE_include_directive : require
// PBF, on a step's last substep (pbf_step_xsph), in sorted order, at the corrected positions and
// velocities, one pass for what the same kernels serve: with vorticity confinement on, ω_i =
// Σ_j V (v_j − v_i) × ∇_j W_ij, the curl of the velocity (|ω| in w); XSPH's v_i + c Σ_j V (v_j −
// v_i) W_ij (c compounded over the step's substeps) into the state's velocity, which the finish
// pass confines; the compression the step leaves, max(ρ/ρ0 − 1, 0) walls included, for the
// substep rule. As PbfSolver::sum_over_neighbours.
#include "common/core.glsl"
#include "common/sim_params.glsl"
#include "common/sim_kernels.glsl"

void main() {
  load_constants();
  const uint k = invocation();
  float compression = 0.0;
  if (k < P.particle_count) {
    Vec4s x = P.iterate;
    Vec4s velocities = P.sorted_velocity;
    const vec3 p = x.v[k].xyz;
    const vec3 v = velocities.v[k].xyz;
    const bool confine = P.vorticity_epsilon > 0.0;
    vec3 omega = vec3(0.0), smoothing = vec3(0.0);
    float density = poly6(0.0);
    const uint count = neighbour_count(k);
    for (uint g = 0u; 4u * g < count; ++g) {
      const uvec4 j = neighbour_group(k, g);
      const vec4 others[4] = gather(x, j), other_velocities[4] = gather(velocities, j);
      [[unroll]] for (uint l = 0u; l < 4u; ++l) {
        if (4u * g + l == count) break;
        const vec3 r = p - others[l].xyz;
        const float r2 = dot(r, r);
        if (!(r2 < K_h2)) continue;
        const vec3 relative = other_velocities[l].xyz - v;
        if (confine) omega += cross(relative, -spiky_gradient(r, r2));
        const float w = poly6(r2);
        smoothing += relative * w;
        density += w;
      }
    }
    if (confine) {
      omega *= P.rest_volume;
      const float omega_length = length(omega);
      P.vorticity.v[k] = vec4(omega, omega_length);
      // The λ there are spent: the finish pass gathers |ω| beside the positions instead.
      P.iterate_scalar.v[k] = vec4(p, omega_length);
    }
    P.velocity.v[k] = vec4(v + P.xsph * P.rest_volume * smoothing, 0.0);
    compression = max((P.mass * density + walls(p).x) * P.inv_rest_density - 1.0, 0.0);
  }
  record_sum(2u, compression);
}

#version 460
#extension GL_GOOGLE_include_directive : require
// PBF, last pass of a step's last substep: vorticity confinement (a = ε N × ω, over the whole
// step) on the velocity pbf_sums.comp smoothed; then the substep's end (end_pbf_substep: the
// state written back, the speed and wall approach recorded).
#include "common/core.glsl"
#include "common/sim_params.glsl"
#include "common/sim_kernels.glsl"

void main() {
  load_constants();
  const uint k = invocation();
  const bool in_range = k < P.particle_count;
  vec3 p = vec3(0.0), velocity = vec3(0.0);
  if (in_range) {
    p = P.iterate.v[k].xyz;
    // The sums pass wrote the smoothed velocity in place of the state's, which the reorder has
    // already read.
    velocity = P.velocity.v[k].xyz;
    if (P.vorticity_epsilon > 0.0) {
      const vec4 omega = P.vorticity.v[k];
      // Positions with |ω| in w, as the sums pass left them.
      Vec4s x = P.iterate_scalar;
      vec3 eta = vec3(0.0);
      const uint count = neighbour_count(k);
      for (uint g = 0u; 4u * g < count; ++g) {
        const vec4 others[4] = gather(x, neighbour_group(k, g));
        [[unroll]] for (uint l = 0u; l < 4u; ++l) {
          if (4u * g + l == count) break;
          const vec3 r = p - others[l].xyz;
          const float r2 = dot(r, r);
          if (r2 < K_h2) eta += (others[l].w - omega.w) * spiky_gradient(r, r2);
        }
      }
      const float eta_length = length(eta);
      if (eta_length > 1e-12) {
        // On the step's last substep, seconds into the step are its length.
        velocity += pass.time_into_step * P.vorticity_epsilon * cross(eta / eta_length, omega.xyz);
      }
    }
  }
  // The filters may add speed: held as PbfSolver::finish_step holds it.
  end_pbf_substep(k, in_range, p, held_to_max_speed(velocity));
}

#version 460
#extension GL_GOOGLE_include_directive : require
// PBF, last pass of a substep: on a step's last, vorticity confinement (a = ε N × ω, over the
// whole step) on the velocity pbf_sums.comp smoothed; then the particles written back as state
// (sorted order becomes state order), and the largest |v|² and wall approach recorded for the
// next step's substep count.
#include "common/core.glsl"
#include "common/sim_params.glsl"
#include "common/sim_kernels.glsl"

void main() {
  load_constants();
  const uint k = invocation();
  float speed2 = 0.0, approach = 0.0;
  if (k < P.particle_count) {
    Vec4s x = P.iterate;
    const vec3 p = x.v[k].xyz;
    // On a step's last substep the sums pass wrote the smoothed velocity in place of the state's,
    // which the reorder has already read; on the others the last correction's stands.
    const bool step_end = pass.last_substep != 0u;
    vec3 velocity = step_end ? P.velocity.v[k].xyz : P.sorted_velocity.v[k].xyz;
    if (step_end && P.vorticity_epsilon > 0.0) {
      Vec4s vorticity = P.vorticity;
      const vec4 omega = vorticity.v[k];
      vec3 eta = vec3(0.0);
      for (uint e = 0u, count = neighbour_count(k); e < count; ++e) {
        const uint j = neighbour(k, e);
        const vec3 r = p - x.v[j].xyz;
        const float r2 = dot(r, r);
        if (!(r2 < K_h2)) continue;
        const vec4 omega_j = vorticity.v[j];
        eta += (omega_j.w - omega.w) * spiky_gradient(r, r2);
      }
      const float eta_length = length(eta);
      if (eta_length > 1e-12) {
        // On the last substep, seconds into the step are the step's length.
        velocity += pass.time_into_step * P.vorticity_epsilon * cross(eta / eta_length, omega.xyz);
      }
    }
    P.position.v[k] = vec4(p, 0.0);
    P.velocity.v[k] = vec4(velocity, 0.0);
    P.id.v[k] = P.sorted_id.v[k];
    speed2 = dot(velocity, velocity);
    approach = wall_approach(p, velocity);
  }
  record_largest(0u, speed2);
  record_largest(4u, approach);
}

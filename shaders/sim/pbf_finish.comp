#version 460
#extension GL_GOOGLE_include_directive : require
// PBF, last pass of a substep: vorticity confinement (a = ε N × ω) and XSPH viscosity on the
// velocity, then the particles written back as state (sorted order becomes state order), and the
// largest |v|² and wall approach recorded for the next step's substep count; on a step's last
// substep also the compression it leaves, max(ρ/ρ0 − 1, 0) walls included, for the substep rule
// (as PbfSolver::sum_over_neighbours measures it).
#include "common/core.glsl"
#include "common/sim_params.glsl"
#include "common/sim_kernels.glsl"

void main() {
  load_constants();
  const uint k = invocation();
  float speed2 = 0.0, approach = 0.0, compression = 0.0;
  if (k < P.particle_count) {
    Vec4s x = P.iterate;
    const vec3 p = x.v[k].xyz;
    Vec4s velocities = P.sorted_velocity, vorticity = P.vorticity;
    const vec3 v = velocities.v[k].xyz;
    vec3 velocity = v;
    const bool measure = pass.record_compression != 0u;
    if (P.vorticity_epsilon > 0.0 || P.xsph > 0.0 || measure) {
      const bool confine = P.vorticity_epsilon > 0.0;
      float density = poly6(0.0);
      const vec4 omega = confine ? vorticity.v[k] : vec4(0.0);
      vec3 eta = vec3(0.0), smoothing = vec3(0.0);
      for (uint e = 0u, count = neighbour_count(k); e < count; ++e) {
        const uint j = neighbour(k, e);
        const vec3 r = p - x.v[j].xyz;
        const float r2 = dot(r, r);
        if (!(r2 < K_h2)) continue;
        if (confine) {
          const vec4 omega_j = vorticity.v[j];
          eta += (omega_j.w - omega.w) * spiky_gradient(r, r2);
        }
        const float w = poly6(r2);
        smoothing += (velocities.v[j].xyz - v) * w;
        density += w;
      }
      compression = max((P.mass * density + walls(p).x) * P.inv_rest_density - 1.0, 0.0);
      velocity += P.xsph * P.rest_volume * smoothing;
      const float eta_length = length(eta);
      if (confine && eta_length > 1e-12) {
        velocity += pass.dt * P.vorticity_epsilon * cross(eta / eta_length, omega.xyz);
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
  if (pass.record_compression != 0u) record_sum(2u, compression);
}

#version 460
#extension GL_GOOGLE_include_directive : require
// SPH: a_i = g − Σ m (p_i/ρ_i² + p_j/ρ_j² + Π_ij) ∇W + μ/ρ_i Σ m (v_j − v_i)/ρ_j ∇²W + walls,
// as SphSolver::compute_accelerations; records the largest |a| for the next step's substeps.
#include "common/core.glsl"
#include "common/sim_params.glsl"
#include "common/sim_kernels.glsl"

void main() {
  load_constants();
  const uint k = invocation();
  float largest = 0.0;
  if (k < P.particle_count) {
    Vec4s x = P.sorted_position, velocity = P.sorted_velocity;
    Vec2s density = P.density;
    const float artificial_viscosity = P.artificial_viscosity, softening = P.softening;
    const vec3 p = x.v[k].xyz;
    const vec3 v = velocity.v[k].xyz;
    const vec2 own = density.v[k];
    const float pressure_term_i = own.y / (own.x * own.x);
    vec3 pressure_acceleration = vec3(0.0), viscous_sum = vec3(0.0);
    const uint count = neighbour_count(k);
    for (uint g = 0u; 4u * g < count; ++g) {
      const uvec4 j = neighbour_group(k, g);
      const vec4 others[4] = gather(x, j), other_velocities[4] = gather(velocity, j);
      const vec2 other_densities[4] = gather_pairs(density, j);
      [[unroll]] for (uint l = 0u; l < 4u; ++l) {
        if (4u * g + l == count) break;
        const vec3 r = p - others[l].xyz;
        const float r2 = dot(r, r);
        if (!(r2 < K_h2)) continue;
        const float distance = sqrt(r2);
        const vec2 other = other_densities[l];
        const vec3 vj = other_velocities[l].xyz;
        float pair = pressure_term_i + other.y / (other.x * other.x);
        const float approach = dot(v - vj, r);
        if (approach < 0.0) {
          pair -= artificial_viscosity / (own.x + other.x) * approach /
                  (distance * distance + softening);
        }
        pressure_acceleration -= pair * spiky_gradient(r, r2);
        viscous_sum += (vj - v) * (viscosity_laplacian(distance) / other.x);
      }
    }
    const vec3 wall_acceleration = -2.0 * pressure_term_i * walls(p).yzw;
    const vec3 a = P.gravity.xyz + P.mass * pressure_acceleration + wall_acceleration +
                   (P.sph_viscosity * P.mass / own.x) * viscous_sum;
    P.acceleration.v[k] = vec4(a, 0.0);
    largest = length(a);
  }
  record_largest(1u, largest);
}

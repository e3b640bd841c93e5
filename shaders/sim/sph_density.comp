#version 460
#extension GL_GOOGLE_include_directive : require
// SPH: density (poly6, walls as fluid at rest) and Tait pressure, clamped at 0; as
// SphSolver::compute_densities_and_pressures.
#include "common/core.glsl"
#include "common/sim_params.glsl"
#include "common/sim_kernels.glsl"

void main() {
  load_constants();
  const uint k = invocation();
  if (k >= P.particle_count) return;
  Vec4s x = P.sorted_position;
  const vec3 p = x.v[k].xyz;
  float sum = poly6(0.0);
  for (uint e = 0u, count = neighbour_count(k); e < count; ++e) {
    const uint j = neighbour(k, e);
    const vec3 r = p - x.v[j].xyz;
    const float r2 = dot(r, r);
    if (!(r2 < K_h2)) continue;
    sum += poly6(r2);
  }
  const float density = P.mass * sum + walls(p).x;
  const float pressure =
      max(0.0, P.tait_stiffness * (pow(density / P.rest_density, P.tait_exponent) - 1.0));
  P.density.v[k] = vec2(density, pressure);
  P.density_ratio.v[k] = density * P.inv_rest_density;  // state index k once the substep ends
}

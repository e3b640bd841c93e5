#version 460
#extension GL_GOOGLE_include_directive : require
// PBF: the density constraint's λ (Macklin & Müller 2013), unilateral (only compression), with
// the walls as fluid at rest; as PbfSolver::compute_lambdas.
#include "common/core.glsl"
#include "common/sim_params.glsl"
#include "common/sim_kernels.glsl"

void main() {
  load_constants();
  const uint k = invocation();
  if (k >= P.particle_count) return;
  Vec4s x = P.iterate;
  const vec3 p = x.v[k].xyz;
  const float rest_volume = P.rest_volume;
  float density = poly6(0.0);
  vec3 gradient_i = vec3(0.0);
  float sum_squares = 0.0;
  for (uint e = 0u, count = neighbour_count(k); e < count; ++e) {
    const uint j = neighbour(k, e);
    const vec3 r = p - x.v[j].xyz;
    const float r2 = dot(r, r);
    if (!(r2 < K_h2)) continue;
    density += poly6(r2);
    const vec3 g = rest_volume * spiky_gradient(r, r2);
    gradient_i += g;
    sum_squares += dot(g, g);
  }
  const vec4 wall = walls(p);
  gradient_i += P.inv_rest_density * wall.yzw;
  const float ratio = (P.mass * density + wall.x) * P.inv_rest_density;
  P.density_ratio.v[k] = ratio;  // sorted slot k is state index k once the substep ends
  const float constraint = max(ratio - 1.0, 0.0);
  const float lambda = constraint == 0.0 ? 0.0
      : -constraint / (sum_squares + dot(gradient_i, gradient_i) + P.relaxation_epsilon);
  P.iterate_lambda.v[k] = vec4(p, lambda);
}

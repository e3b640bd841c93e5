#version 460
#extension GL_GOOGLE_include_directive : require
// PBF, every iteration after the first (whose λ neighbours.comp computes as it lists): λ at the
// positions the last correction left (density_sums.glsl).
#include "common/core.glsl"
#include "common/sim_params.glsl"
#include "common/sim_kernels.glsl"
#include "common/density_sums.glsl"

void main() {
  load_constants();
  const uint k = invocation();
  if (k >= P.particle_count) return;
  Vec4s x = P.iterate;
  const vec3 p = x.v[k].xyz;
  LambdaSum sum = lambda_sum_start();
  for (uint e = 0u, count = neighbour_count(k); e < count; ++e) {
    const uint j = neighbour(k, e);
    const vec3 r = p - x.v[j].xyz;
    const float r2 = dot(r, r);
    if (!(r2 < K_h2)) continue;
    lambda_sum_add(sum, r, r2);
  }
  write_lambda(k, p, sum);
}

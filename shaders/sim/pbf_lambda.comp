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
  const uint count = neighbour_count(k);
  for (uint g = 0u; 4u * g < count; ++g) {
    const vec4 others[4] = gather(x, neighbour_group(k, g));
    [[unroll]] for (uint l = 0u; l < 4u; ++l) {
      if (4u * g + l == count) break;
      const vec3 r = p - others[l].xyz;
      const float r2 = dot(r, r);
      if (r2 < K_h2) lambda_sum_add(sum, r, r2);
    }
  }
  write_lambda(k, p, sum);
}

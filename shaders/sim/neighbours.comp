#version 460
#extension GL_GOOGLE_include_directive : require
// Lists, once per substep, every particle's neighbours: the others within h of it at the
// positions the substep begins with (PBF: the predictions; SPH: the state), found among the
// candidates of its cell's window, in their order, at most max_neighbours. Every later pass of
// the substep reads the list (about a third of the candidates, and no cell arithmetic), as the
// CPU solvers read theirs. As it lists, it adds up what the substep first needs of the same
// neighbours (density_sums.glsl): PBF's first λ, SPH's density and pressure.
#include "common/core.glsl"
#include "common/sim_params.glsl"
#include "common/sim_kernels.glsl"
#include "common/density_sums.glsl"

void main() {
  load_constants();
  const uint k = invocation();
  if (k >= P.particle_count) return;
  const bool pbf = P.solver == SOLVER_PBF;
  Vec4s x = pbf ? P.iterate : P.sorted_position;
  const vec3 p = x.v[k].xyz;
  const uint most = P.max_neighbours;
  uint count = 0u;
  uvec4 group = uvec4(k);  // the list's entries come out four at a time; k fills a last group
  LambdaSum lambda = lambda_sum_start();
  float density_sum = poly6(0.0);
  const ivec3 cell = sorted_cell(k);
  FOR_EACH_CANDIDATE(cell, j) {
    if (count == most) continue;  // a clump: the list is full, the window (bounded) passed over
    const vec3 r = p - x.v[j].xyz;
    const float r2 = dot(r, r);
    if (!(r2 < K_h2) || j == k) continue;
    group = mix(group, uvec4(j), equal(uvec4(0u, 1u, 2u, 3u), uvec4(count & 3u)));
    ++count;
    if ((count & 3u) == 0u) {
      K_neighbours.v[k + ((count >> 2) - 1u) * K_particle_count] = group;
      group = uvec4(k);
    }
    if (pbf) {
      lambda_sum_add(lambda, r, r2);
    } else {
      density_sum += poly6(r2);
    }
  }
  if ((count & 3u) != 0u) K_neighbours.v[k + (count >> 2) * K_particle_count] = group;
  K_neighbour_count.v[k] = count;
  if (pbf) {
    write_lambda(k, p, lambda);
  } else {
    write_sph_density(k, p, density_sum);
  }
}

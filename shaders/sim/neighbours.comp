#version 460
#extension GL_GOOGLE_include_directive : require
// Lists, once per substep, every particle's neighbours: the others within h of it at the
// positions the substep begins with (PBF: the predictions; SPH: the state), found among the
// candidates of its cell's window, in their order, at most max_neighbours. Every later pass of
// the substep reads the list (about a third of the candidates, and no cell arithmetic), as the
// CPU solvers read theirs.
#include "common/core.glsl"
#include "common/sim_params.glsl"
#include "common/sim_kernels.glsl"

void main() {
  load_constants();
  const uint k = invocation();
  if (k >= P.particle_count) return;
  Vec4s x = P.solver == SOLVER_PBF ? P.iterate : P.sorted_position;
  const vec3 p = x.v[k].xyz;
  const uint most = P.max_neighbours;
  uint count = 0u;
  const ivec3 cell = sorted_cell(k);
  FOR_EACH_CANDIDATE(cell, j) {
    if (count == most) continue;  // a clump: the list is full, the window (bounded) passed over
    const vec3 r = p - x.v[j].xyz;
    if (!(dot(r, r) < K_h2) || j == k) continue;
    K_neighbours.v[k + count * K_particle_count] = j;
    ++count;
  }
  K_neighbour_count.v[k] = count;
}

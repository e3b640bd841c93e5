#version 460
#extension GL_GOOGLE_include_directive : require
// The grid's last step and the reorder in one pass, in state order: each particle's sorted slot
// (grid_scatter), and every attribute moved there. The one place where particles are reordered.
#include "common/core.glsl"
#include "common/sim_params.glsl"
#include "common/grid.glsl"

void main() {
  const uint i = invocation();
  if (i >= P.particle_count) return;
  // The references read from the block first: a block member cannot be passed as one.
  Uints cell_of = P.cell_of, rank = P.rank, cell_start = P.cell_start, order = P.order,
        sorted_cell = P.sorted_cell;
  const uint k = grid_scatter(i, cell_of, rank, cell_start, order, sorted_cell);
  P.sorted_position.v[k] = P.position.v[i];
  P.sorted_velocity.v[k] = P.velocity.v[i];
  P.sorted_id.v[k] = P.id.v[i];
  if (P.solver == SOLVER_PBF) P.iterate.v[k] = P.predicted.v[i];
}

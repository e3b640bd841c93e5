// Push constants of the grid's count and scatter passes; mirrored by GridPass in
// core/sim/gpu/gpu_neighbour_grid.cpp.
layout(push_constant, std430) uniform GridPass {
  Vec4s key;         // positions to sort by
  Uints cell_of;     // per particle: its cell
  Uints rank;        // per particle: its place within its cell, from the atomic count
  Uints cell_start;  // per cell: the count, then (after the prefix sum) the first sorted slot; +1
  Uints order;       // per sorted slot: the particle
  Uints sorted_cell; // per sorted slot: the cell of its particle
  vec4 origin;       // xyz: the grid's origin; w: 1 / cell size
  ivec4 dims;        // xyz: cells per axis
  uint particle_count;
} pass;

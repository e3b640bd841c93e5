// The uniform grid's geometry, as GridGeometry in core/include/fluidcast/sim/neighbour_grid.h
// computes it: the same float operations, so that GPU and CPU put a particle in the same cell.

ivec3 grid_cell_coords(vec3 p, vec3 origin, float inv_cell_size, ivec3 dims) {
  const vec3 f = floor((p - origin) * inv_cell_size);
  // Clamp in float first (a far-away position must not overflow the int conversion); NaN → 0.
  vec3 clamped = min(max(f, vec3(0.0)), vec3(dims - 1));
  clamped = mix(clamped, vec3(0.0), isnan(f));
  return ivec3(clamped);
}

uint grid_cell_index(ivec3 c, ivec3 dims) { return uint(c.x + dims.x * (c.y + dims.y * c.z)); }

// Counting sort, step 1, for particle i at p: its cell, and its rank in the cell from an atomic
// count into cell_start (cleared before). The grid's own pass runs it, and PBF's prediction as it
// predicts, to save a pass. origin: xyz the grid's origin, w 1 / cell size.
void grid_count(uint i, vec3 p, vec4 origin, ivec3 dims, Uints cell_of, Uints rank,
                Uints cell_start) {
  const uint cell = grid_cell_index(grid_cell_coords(p, origin.xyz, origin.w, dims), dims);
  cell_of.v[i] = cell;
  rank.v[i] = atomicAdd(cell_start.v[cell], 1u);
}

// Counting sort, step 4, once the counts are prefix-summed: particle i's sorted slot, its cell's
// start plus its rank; the slot records the particle and its cell. The grid's own pass runs it,
// and the solvers' reorder, which moves the particle there in the same pass.
uint grid_scatter(uint i, Uints cell_of, Uints rank, Uints cell_start, Uints order,
                  Uints sorted_cell) {
  const uint cell = cell_of.v[i];
  const uint slot = cell_start.v[cell] + rank.v[i];
  order.v[slot] = i;
  sorted_cell.v[slot] = cell;
  return slot;
}

// Elements per invocation of the prefix sum (GpuNeighbourGrid::kScanItemsPerInvocation).
#define SCAN_ITEMS_PER_INVOCATION 16

// For every sorted slot j in the 5×5 rows of 5 cells around `cell` (cells are half the search
// radius; a row's slots are contiguous), the first `most` of them (a clump's cost stays bounded,
// as NeighbourList's on the CPU): cell_start (Uints) and dims (ivec3) are the grid's.
#define FOR_EACH_CANDIDATE_IN(cell_start, dims, cell, j, most)                                    \
  for (uint examined_ = 0u, once_ = 1u; once_ != 0u; once_ = 0u)                                  \
    for (int z_ = max(cell.z - 2, 0); z_ <= min(cell.z + 2, dims.z - 1) && examined_ < (most);    \
         ++z_)                                                                                    \
      for (int y_ = max(cell.y - 2, 0); y_ <= min(cell.y + 2, dims.y - 1) && examined_ < (most);  \
           ++y_)                                                                                  \
        for (uint j = cell_start.v[grid_cell_index(ivec3(max(cell.x - 2, 0), y_, z_), dims)],     \
                  end_ = cell_start.v[grid_cell_index(ivec3(min(cell.x + 2, dims.x - 1), y_, z_), \
                                                      dims) + 1];                                 \
             j < end_ && examined_ < (most); ++j, ++examined_)

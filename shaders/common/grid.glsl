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

// Elements per invocation of the prefix sum (GpuNeighbourGrid::kScanItemsPerInvocation).
#define SCAN_ITEMS_PER_INVOCATION 4

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

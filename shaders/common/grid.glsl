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

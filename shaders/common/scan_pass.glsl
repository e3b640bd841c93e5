// Push constants of the prefix-sum passes; mirrored by ScanPass in gpu_neighbour_grid.cpp.
layout(push_constant, std430) uniform ScanPass {
  Uints data;        // scanned in place
  Uints block_sums;  // one total per block of gl_WorkGroupSize.x * SCAN_ITEMS_PER_INVOCATION
  uint count;
  uint write_block_sums;
} pass;

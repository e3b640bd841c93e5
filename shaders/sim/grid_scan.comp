#version 460
#extension GL_GOOGLE_include_directive : require
// Counting sort, step 2: exclusive prefix sum of one block per workgroup, in place; the block's
// total goes to block_sums, whose own prefix sum (the next level) grid_scan_add.comp adds back.
// Each invocation scans SCAN_ITEMS_PER_INVOCATION consecutive elements serially, then the
// workgroup scans the invocations' totals in shared memory (Hillis–Steele).
#include "common/core.glsl"
#include "common/grid.glsl"
#include "common/scan_pass.glsl"

shared uint totals[2][gl_WorkGroupSize.x];

void main() {
  const uint block = linear_group();
  const uint t = gl_LocalInvocationID.x;
  const uint first = (block * gl_WorkGroupSize.x + t) * SCAN_ITEMS_PER_INVOCATION;
  uint items[SCAN_ITEMS_PER_INVOCATION];
  uint sum = 0;
  for (uint k = 0; k < SCAN_ITEMS_PER_INVOCATION; ++k) {
    const uint e = first + k;
    const uint value = e < pass.count ? pass.data.v[e] : 0u;
    items[k] = sum;
    sum += value;
  }
  uint from = 0;
  totals[from][t] = sum;
  barrier();
  for (uint offset = 1; offset < gl_WorkGroupSize.x; offset *= 2) {
    const uint to = 1 - from;
    totals[to][t] = totals[from][t] + (t >= offset ? totals[from][t - offset] : 0u);
    from = to;
    barrier();
  }
  const uint before = totals[from][t] - sum;  // exclusive
  for (uint k = 0; k < SCAN_ITEMS_PER_INVOCATION; ++k) {
    const uint e = first + k;
    if (e < pass.count) pass.data.v[e] = before + items[k];
  }
  // Groups past the last block exist when the dispatch spills into y.
  const bool real_block = block * gl_WorkGroupSize.x * SCAN_ITEMS_PER_INVOCATION < pass.count;
  if (pass.write_block_sums != 0 && real_block && t == gl_WorkGroupSize.x - 1) {
    pass.block_sums.v[block] = totals[from][t];
  }
}

#version 460
#extension GL_GOOGLE_include_directive : require
// Counting sort, step 3: adds each block's offset (the scanned block totals) to its elements.
#include "common/core.glsl"
#include "common/grid.glsl"
#include "common/scan_pass.glsl"

void main() {
  const uint e = invocation();
  if (e >= pass.count) return;
  const uint block = e / (gl_WorkGroupSize.x * SCAN_ITEMS_PER_INVOCATION);
  pass.data.v[e] += pass.block_sums.v[block];
}

#version 460
#extension GL_GOOGLE_include_directive : require
// Marching Cubes, field step 2: a separable Gaussian blur of the splat, one axis per pass (x, y,
// z), normalised so that fluid at rest comes out as 1 (the weights sum to 1; nodes beyond the
// grid count as 0). Per node a row of reads, no atomics.
#include "common/core.glsl"
#include "common/mc_pass.glsl"

void main() {
  const uint index = invocation();
  const ivec4 nodes = pass.nodes;
  if (index >= uint(nodes.x * nodes.y * nodes.z)) return;
  const ivec3 node = ivec3(int(index) % nodes.x, (int(index) / nodes.x) % nodes.y,
                           int(index) / (nodes.x * nodes.y));
  const int axis = pass.axis, reach = pass.reach;
  // Selects rather than indexing a vector by `axis`, which compilers may spill to memory.
  const int along = axis == 0 ? node.x : (axis == 1 ? node.y : node.z);
  const int size = axis == 0 ? nodes.x : (axis == 1 ? nodes.y : nodes.z);
  const int stride = axis == 0 ? 1 : (axis == 1 ? nodes.x : nodes.x * nodes.y);
  // Uniform loop bounds (every lane the same taps); taps beyond the grid read a clamped node
  // and weigh 0.
  Floats blur_in = pass.blur_in;
  Uints splat = pass.splat;
  Ints tables = pass.tables;
  float sum = 0.0;
  for (int k = -reach; k <= reach; ++k) {
    const int at = along + k;
    const bool inside = at >= 0 && at < size;
    const int j = int(index) + (clamp(at, 0, size - 1) - along) * stride;
    const float value = axis == 0 ? float(splat.v[j]) * kSplatUnit : blur_in.v[j];
    sum += inside ? intBitsToFloat(tables.v[kBlurWeightsAt + k + reach]) * value : 0.0;
  }
  pass.blur_out.v[index] = sum;
  // The x pass has read the splat: clear it for the next frame here rather than in a pass of its
  // own.
  if (axis == 1) splat.v[index] = 0u;
}

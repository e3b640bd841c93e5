#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
// Marching Cubes, field step 2: a separable Gaussian blur of the splat, one axis per pass (x, y,
// z), normalised so that fluid at rest comes out as 1 (the weights sum to 1; nodes beyond the
// grid count as 0). Per node a row of reads, no atomics.
#include "common/core.glsl"
#include "common/mc_pass.glsl"

// Taps on each side (⌈3σ⌉, at most 16) and the weights of taps 0 to 16 (a Gaussian summing to 1
// over the taps), set by MarchingCubes: constants the driver folds into the unrolled loop.
layout(constant_id = 1) const int kReach = 3;
layout(constant_id = 2) const float kWeight0 = 0.0;
layout(constant_id = 3) const float kWeight1 = 0.0;
layout(constant_id = 4) const float kWeight2 = 0.0;
layout(constant_id = 5) const float kWeight3 = 0.0;
layout(constant_id = 6) const float kWeight4 = 0.0;
layout(constant_id = 7) const float kWeight5 = 0.0;
layout(constant_id = 8) const float kWeight6 = 0.0;
layout(constant_id = 9) const float kWeight7 = 0.0;
layout(constant_id = 10) const float kWeight8 = 0.0;
layout(constant_id = 11) const float kWeight9 = 0.0;
layout(constant_id = 12) const float kWeight10 = 0.0;
layout(constant_id = 13) const float kWeight11 = 0.0;
layout(constant_id = 14) const float kWeight12 = 0.0;
layout(constant_id = 15) const float kWeight13 = 0.0;
layout(constant_id = 16) const float kWeight14 = 0.0;
layout(constant_id = 17) const float kWeight15 = 0.0;
layout(constant_id = 18) const float kWeight16 = 0.0;
float weight(int k) {  // a switch, not an array: arrays of specialisation constants are not constant
  switch (abs(k)) {
    case 0: return kWeight0;
    case 1: return kWeight1;
    case 2: return kWeight2;
    case 3: return kWeight3;
    case 4: return kWeight4;
    case 5: return kWeight5;
    case 6: return kWeight6;
    case 7: return kWeight7;
    case 8: return kWeight8;
    case 9: return kWeight9;
    case 10: return kWeight10;
    case 11: return kWeight11;
    case 12: return kWeight12;
    case 13: return kWeight13;
    case 14: return kWeight14;
    case 15: return kWeight15;
    case 16: return kWeight16;
    default: return 0.0;
  }
}

void main() {
  const uint index = invocation();
  const ivec4 nodes = pass.nodes;
  if (index >= uint(nodes.x * nodes.y * nodes.z)) return;
  const ivec3 node = ivec3(int(index) % nodes.x, (int(index) / nodes.x) % nodes.y,
                           int(index) / (nodes.x * nodes.y));
  const int axis = pass.axis;
  // Selects rather than indexing a vector by `axis`, which compilers may spill to memory.
  const int along = axis == 0 ? node.x : (axis == 1 ? node.y : node.z);
  const int size = axis == 0 ? nodes.x : (axis == 1 ? nodes.y : nodes.z);
  const int stride = axis == 0 ? 1 : (axis == 1 ? nodes.x : nodes.x * nodes.y);
  // Straight-line code for CPU drivers (lavapipe): taps and weights are constants the driver
  // unrolls and folds, every lane reads the same taps (beyond the grid a clamped node, weighed
  // 0), and the x pass's different input is chosen once.
  const bool from_splat = axis == 0;
  Floats blur_in = pass.blur_in;
  Uints splat = pass.splat;
  float sum = 0.0;
  [[unroll]] for (int k = -kReach; k <= kReach; ++k) {
    const int at = along + k;
    const int j = int(index) + (clamp(at, 0, size - 1) - along) * stride;
    const float value = from_splat ? float(splat.v[j]) * kSplatUnit : blur_in.v[j];
    sum += at >= 0 && at < size ? weight(k) * value : 0.0;
  }
  pass.blur_out.v[index] = sum;
  // The x pass has read the splat: clear it for the next frame here rather than in a pass of its
  // own.
  if (axis == 1) splat.v[index] = 0u;
}

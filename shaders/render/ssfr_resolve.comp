#version 460
#extension GL_GOOGLE_include_directive : require
// After SSFR's particle pass: each pixel's water and spray, summed in fixed point, as the floats
// the filter and the shading read (in place).
#include "common/particle_splat.glsl"

void main() {
  const uint at = invocation();
  if (at >= splat.frame.width * splat.frame.height) return;
  splat.thickness.v[at] = floatBitsToUint(float(splat.thickness.v[at]) * kThicknessUnit);
  splat.spray.v[at] = floatBitsToUint(float(splat.spray.v[at]) * kSprayUnit);
}

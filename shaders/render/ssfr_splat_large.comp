#version 460
#extension GL_GOOGLE_include_directive : require
// SSFR's particle pass for the particles ssfr_splat queued (common/ssfr_splat.glsl): a workgroup
// per particle, dispatched indirectly as many as were queued, its invocations taking every
// group-size-th pixel.
#include "common/ssfr_splat.glsl"

void main() {
  Particle p;
  if (!particle_in_view(splat.large.v[4u + linear_group()], p)) return;
  splat_pixels(p, gl_LocalInvocationID.x, gl_WorkGroupSize.x);
}

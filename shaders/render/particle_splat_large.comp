#version 460
#extension GL_GOOGLE_include_directive : require
// The particle passes for the particles particle_splat queued (common/particle_splat.glsl): a
// workgroup per particle, dispatched indirectly as many as were queued, its invocations taking
// every group-size-th pixel.
#include "common/particle_splat.glsl"

void main() {
  Particle p;
  if (!particle_in_view(splat.large.v[4u + linear_group()], p)) return;
  splat_pixels(p, gl_LocalInvocationID.x, gl_WorkGroupSize.x);
}

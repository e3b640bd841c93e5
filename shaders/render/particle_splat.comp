#version 460
#extension GL_GOOGLE_include_directive : require
// The particle passes (common/particle_splat.glsl): one invocation per particle. A small one's
// pixels are cast here, one after the other; a larger one is queued for particle_splat_large,
// whose workgroup shares its pixels, unless the queue is full.
#include "common/particle_splat.glsl"

void main() {
  const uint index = invocation();
  if (index >= splat.particle_count) return;
  Particle p;
  if (!particle_in_view(index, p)) return;
  if (pixels_of(p) > kInlinePixels) {
    const uint slot = atomicAdd(splat.large.v[3], 1u);
    if (slot < splat.large_capacity) {
      splat.large.v[4u + slot] = index;
      atomicAdd(splat.large.v[0], 1u);
      return;
    }
  }
  splat_pixels(p, 0u, 1u);
}

#version 460
#extension GL_GOOGLE_include_directive : require
// SSFR, depth smoothing: one direction of the separable bilateral filter (van der Laan et al.
// 2009). The radius is a length in the scene, so it covers fewer pixels far away
// (view-invariant, as the talk recommends); the range weight keeps silhouettes sharp.
#include "common/frame.glsl"
#include "common/screen_pass.glsl"

// Pixels without fluid hold +infinity (the depth buffer is cleared to its bits).
float infinity() { return uintBitsToFloat(0x7f800000u); }

void main() {
  const uint width = screen.frame.width, height = screen.frame.height;
  const uint index = invocation();  // one per pixel, rows one after the other
  if (index >= width * height) return;
  const uvec2 p = uvec2(index % width, index / width);
  const float centre = screen.depth_in.v[index];
  if (centre == infinity()) {
    screen.depth_out.v[index] = infinity();
    return;
  }
  const mat4 projection = screen.frame.projection;
  const float pixels_per_metre = 0.5 * float(height) * abs(projection[1][1]) / centre;
  const int radius = clamp(int(screen.frame.smoothing_radius * pixels_per_metre), 1, 24);
  const float sigma = max(float(radius) * 0.5, 0.5);
  const float falloff = screen.frame.depth_falloff;
  const ivec2 step = screen.axis == 0u ? ivec2(1, 0) : ivec2(0, 1);
  float sum = 0.0, weights = 0.0;
  for (int k = -radius; k <= radius; ++k) {
    const ivec2 q = ivec2(p) + k * step;
    if (q.x < 0 || q.y < 0 || q.x >= int(width) || q.y >= int(height)) continue;
    const float d = screen.depth_in.v[uint(q.y) * width + uint(q.x)];
    const bool narrow = screen.narrow_range != 0u;
    if (d == infinity() && !narrow) continue;
    const float spatial = exp(-float(k * k) / (2.0 * sigma * sigma));
    float value = d, weight = spatial;
    if (narrow) {
      if (d < centre - falloff) continue;  // in front: another surface
      // Far behind, background included: as if just behind, so silhouettes round off.
      if (d > centre + falloff) value = centre + screen.frame.particle_radius;
    } else {
      const float difference = (d - centre) / falloff;
      weight *= exp(-difference * difference);
    }
    sum += value * weight;
    weights += weight;
  }
  screen.depth_out.v[index] = sum / weights;
}

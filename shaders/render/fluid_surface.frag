#version 460
#extension GL_GOOGLE_include_directive : require
// SSFR, first pass: each particle a sphere; per pixel, the nearest sphere surface (atomic min of
// the view distance) and the summed thickness of water crossed (atomic add). Early depth tests
// against the scene leave out fluid behind it; nothing is written to the attachments.
#include "common/frame.glsl"
#include "common/draw_pass.glsl"

layout(early_fragment_tests) in;
layout(location = 0) in vec2 corner;
layout(location = 1) in vec3 view_centre;
layout(location = 2) in vec3 colour;

void main() {
  const float r2 = dot(corner, corner);
  if (r2 > 1.0) return;
  const float radius = draw.frame.particle_radius;
  const float half_chord = sqrt(1.0 - r2) * radius;
  const float distance = -(view_centre.z + half_chord);  // view space looks along −z
  const uint pixel = uint(gl_FragCoord.y) * draw.frame.width + uint(gl_FragCoord.x);
  atomicMin(draw.depth.v[pixel], floatBitsToUint(max(distance, 1e-4)));  // never 0: it divides
  atomicAdd(draw.thickness.v[pixel], uint(2.0 * half_chord / kThicknessUnit));
}

#version 460
#extension GL_GOOGLE_include_directive : require
// SSFR, the spheres: each particle's view distance and chord through the pixel, into two float
// attachments that the blend units combine, the distance by minimum (the nearest sphere) and the
// chord by sum (the water crossed). Early depth tests against the scene's depth leave out fluid
// behind it; nothing writes depth.
#include "common/frame.glsl"
#include "common/draw_pass.glsl"

layout(early_fragment_tests) in;
layout(location = 0) in vec2 corner;
layout(location = 1) in vec3 view_centre;
layout(location = 2) in vec3 colour;
layout(location = 0) out float out_distance;
layout(location = 1) out float out_thickness;

void main() {
  const float r2 = dot(corner, corner);
  if (r2 > 1.0) discard;
  const float half_chord = sqrt(1.0 - r2) * draw.frame.particle_radius;
  out_distance = max(-(view_centre.z + half_chord), 1e-4);  // looks along −z; never 0: it divides
  out_thickness = 2.0 * half_chord;
}

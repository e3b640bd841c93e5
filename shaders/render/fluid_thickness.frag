#version 460
#extension GL_GOOGLE_include_directive : require
// SSFR, the thickness: each particle's chord through the pixel, summed by additive blending over
// every sphere in front of the scene (tested against the scene's depth only, never written), in
// metres.
#include "common/frame.glsl"
#include "common/draw_pass.glsl"

layout(early_fragment_tests) in;
layout(location = 0) in vec2 corner;
layout(location = 1) in vec3 view_centre;
layout(location = 2) in vec3 colour;
layout(location = 0) out float out_thickness;

void main() {
  const float r2 = dot(corner, corner);
  if (r2 > 1.0) discard;
  out_thickness = 2.0 * sqrt(1.0 - r2) * draw.frame.particle_radius;
}

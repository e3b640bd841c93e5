#version 460
#extension GL_GOOGLE_include_directive : require
// SSFR, the surface: each particle a sphere, through the depth test (the scene's depth copied in
// first, so fluid behind the scene is rejected; then the fluid's own). What survives writes its
// view distance; the nearest sphere's is what stays. Conservative depth keeps early tests on.
#include "common/frame.glsl"
#include "common/draw_pass.glsl"

layout(depth_greater) out float gl_FragDepth;
layout(location = 0) in vec2 corner;
layout(location = 1) in vec3 view_centre;
layout(location = 2) in vec3 colour;
layout(location = 0) out float out_distance;

void main() {
  const float r2 = dot(corner, corner);
  if (r2 > 1.0) discard;
  const float radius = draw.frame.particle_radius;
  const float half_chord = sqrt(1.0 - r2) * radius;
  const vec3 surface = view_centre + vec3(corner * radius, half_chord);
  const vec4 clip = draw.frame.projection * vec4(surface, 1.0);
  gl_FragDepth = clip.z / clip.w;
  out_distance = max(-surface.z, 1e-4);  // view space looks along −z; never 0: it divides
}

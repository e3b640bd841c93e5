#version 460
#extension GL_GOOGLE_include_directive : require
// Points mode: a lit sphere impostor with its true depth, never nearer than the square's
// (points.vert), so early depth tests stay on.
#include "common/frame.glsl"
#include "common/draw_pass.glsl"

layout(depth_greater) out float gl_FragDepth;
layout(location = 0) in vec2 corner;
layout(location = 1) in vec3 view_centre;
layout(location = 2) in vec3 colour;
layout(location = 0) out vec4 out_colour;

void main() {
  const float r2 = dot(corner, corner);
  if (r2 > 1.0) discard;
  const vec3 normal = vec3(corner, sqrt(1.0 - r2));
  const vec3 surface = view_centre + normal * draw.frame.particle_radius;
  const vec4 clip = draw.frame.projection * vec4(surface, 1.0);
  gl_FragDepth = clip.z / clip.w;
  const vec4 light = draw.frame.light_direction;
  const float diffuse = max(dot(normal, normalize(light.xyz)), 0.0);
  out_colour = vec4(colour * (0.3 + 0.7 * diffuse), 1.0);
}

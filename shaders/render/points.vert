#version 460
#extension GL_GOOGLE_include_directive : require
// Each particle becomes a camera-facing square of six vertices (no vertex buffer, no point-size
// limits); points.frag cuts a sphere out of it.
// The square lies in the sphere's centre plane but carries the depth of its front plane, so the
// sphere's true depth, which the fragment shader writes, is never nearer than the square's: with
// conservative depth (depth_greater) the depth test still rejects hidden spheres before shading.
#include "common/frame.glsl"
#include "common/draw_pass.glsl"

layout(location = 0) out vec2 corner;        // −1 to 1 across the square
layout(location = 1) out vec3 view_centre;   // the particle's centre in view space
layout(location = 2) out vec3 colour;

const vec2 kCorners[6] = vec2[](vec2(-1, -1), vec2(1, -1), vec2(1, 1), vec2(-1, -1), vec2(1, 1),
                                vec2(-1, 1));

void main() {
  const uint particle = uint(gl_VertexIndex) / 6u;
  corner = kCorners[uint(gl_VertexIndex) % 6u];
  const mat4 view = draw.frame.view;
  const mat4 projection = draw.frame.projection;
  const float radius = draw.frame.particle_radius;
  const vec4 p = draw.position.v[particle];
  view_centre = (view * vec4(p.xyz, 1.0)).xyz;
  float blend;
  if (draw.frame.colour_by_density != 0u) {
    const float span = draw.frame.density_span;
    blend = clamp((draw.density_ratio.v[particle] - (1.0 - span)) / (2.0 * span), 0.0, 1.0);
  } else {
    const vec4 v = draw.velocity.v[particle];
    blend = clamp(length(v.xyz) / draw.frame.full_speed, 0.0, 1.0);
  }
  const vec4 slow = draw.frame.slow_colour, fast = draw.frame.fast_colour;
  colour = mix(slow.rgb, fast.rgb, blend);
  const vec4 on_centre_plane = projection * vec4(view_centre + vec3(corner * radius, 0.0), 1.0);
  const vec4 on_front_plane = projection * vec4(view_centre + vec3(corner * radius, radius), 1.0);
  gl_Position = vec4(on_centre_plane.xy, on_front_plane.z / on_front_plane.w * on_centre_plane.w,
                     on_centre_plane.w);
}

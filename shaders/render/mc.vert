#version 460
#extension GL_GOOGLE_include_directive : require
// Marching Cubes mesh: vertices (position, normal) read by index from the buffer the compute
// passes wrote.
#include "common/frame.glsl"
#include "common/draw_pass.glsl"

layout(location = 0) out vec3 view_position;
layout(location = 1) out vec3 view_normal;

void main() {
  const uint vertex = uint(gl_VertexIndex);
  const mat4 view = draw.frame.view;
  const vec4 position = draw.vertices.v[2 * vertex];
  const vec4 normal = draw.vertices.v[2 * vertex + 1];
  view_position = (view * vec4(position.xyz, 1.0)).xyz;
  view_normal = mat3(view) * normal.xyz;
  gl_Position = draw.frame.projection * vec4(view_position, 1.0);
}

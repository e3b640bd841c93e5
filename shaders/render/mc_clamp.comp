#version 460
#extension GL_GOOGLE_include_directive : require
// Marching Cubes, step 3: the draw never reads past the vertex buffer, however many cells wanted
// triangles.
#extension GL_EXT_buffer_reference : require
layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer Vec4s { vec4 v[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) buffer Uints { uint v[]; };
#include "common/mc_pass.glsl"

void main() {
  if (mc_invocation() == 0) pass.draw.v[0] = min(pass.draw.v[0], pass.max_vertices);
}

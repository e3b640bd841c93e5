#version 460
#extension GL_GOOGLE_include_directive : require
// Marching Cubes, step 3: the draw never reads past the vertex buffer, however many cells wanted
// triangles.
#include "common/core.glsl"
#include "common/mc_pass.glsl"

void main() {
  if (invocation() == 0) pass.draw.v[0] = min(pass.draw.v[0], pass.max_vertices);
}

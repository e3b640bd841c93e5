#version 460
#extension GL_GOOGLE_include_directive : require
// Marching Cubes into the SSFR buffers, so the mesh gets the same shading: the nearest surface
// (atomic min) and the water crossed, as Σ back-face distances − Σ front-face distances (integer
// atomics; the sum wraps through negative values and ends at the thickness of a closed mesh).
#include "common/frame.glsl"
#include "common/draw_pass.glsl"

layout(location = 0) in vec3 view_position;
layout(location = 1) in vec3 view_normal;

void main() {
  const uint pixel = uint(gl_FragCoord.y) * draw.frame.width + uint(gl_FragCoord.x);
  // The triangle's own plane decides which way it faces; the interpolated normal (outward, from
  // the field) only says which side of that plane is out.
  vec3 face = cross(dFdx(view_position), dFdy(view_position));
  if (dot(face, view_normal) < 0.0) face = -face;
  const bool facing_camera = dot(face, -view_position) > 0.0;
  // Within what the micrometre sum holds (2 km), and never 0: the depth divides later.
  const float along_view = clamp(-view_position.z, 1e-4, 2000.0);
  if (facing_camera) atomicMin(draw.depth.v[pixel], floatBitsToUint(along_view));
  const int signed_length = int(along_view / kThicknessUnit) * (facing_camera ? -1 : 1);
  atomicAdd(draw.thickness.v[pixel], uint(signed_length));
}

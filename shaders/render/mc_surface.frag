#version 460
#extension GL_GOOGLE_include_directive : require
// Marching Cubes into float attachments (FluidTarget), copied where SSFR's particle pass writes,
// so the mesh gets the same shading: the nearest camera-facing surface by minimum blending, and
// the water crossed as Σ back-face distances − Σ front-face distances by additive blending (a
// closed mesh sums to its thickness). No depth test: the mesh closes just outside the tank's walls, behind the scene.
#include "common/frame.glsl"
#include "common/draw_pass.glsl"

layout(location = 0) in vec3 view_position;
layout(location = 1) in vec3 view_normal;
layout(location = 0) out float out_distance;
layout(location = 1) out float out_thickness;
layout(location = 2) out float out_spray;

void main() {
  // The triangle's own plane decides which way it faces; the interpolated normal (outward, from
  // the field) only says which side of that plane is out.
  vec3 face = cross(dFdx(view_position), dFdy(view_position));
  if (dot(face, view_normal) < 0.0) face = -face;
  const bool facing_camera = dot(face, -view_position) > 0.0;
  const float along_view = max(-view_position.z, 1e-4);  // never 0: the depth divides later
  out_distance = facing_camera ? along_view : uintBitsToFloat(0x7f800000u);  // +inf: no change
  out_thickness = facing_camera ? -along_view : along_view;
  out_spray = 0.0;
}

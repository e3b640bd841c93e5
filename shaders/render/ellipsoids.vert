#version 460
#extension GL_GOOGLE_include_directive : require
// SSFR: each particle becomes a camera-facing square of six vertices that covers its ellipsoid
// (anisotropy.comp's, or a sphere of the particle's radius); fluid_surface.frag casts each pixel's
// ray through it. As points.vert does, the square lies in the centre plane but carries the depth
// of the ellipsoid's bounding sphere's front, which no point of the surface is nearer than, so the
// early depth test rejects hidden ones.
#include "common/frame.glsl"
#include "common/draw_pass.glsl"

layout(location = 0) out vec3 offset;            // from the centre to here, view space
layout(location = 1) flat out vec3 view_centre;
layout(location = 2) flat out mat3 to_unit;      // a view-space offset → the unit sphere
layout(location = 5) flat out float spray;       // 1: drawn as spray, not as the surface

const vec2 kCorners[6] = vec2[](vec2(-1, -1), vec2(1, -1), vec2(1, 1), vec2(-1, -1), vec2(1, 1),
                                vec2(-1, 1));

void main() {
  const uint particle = uint(gl_VertexIndex) / 6u;
  const vec2 corner = kCorners[uint(gl_VertexIndex) % 6u];
  const mat4 view = draw.frame.view;
  const float radius = draw.frame.particle_radius;
  const vec4 p = draw.position.v[particle];
  mat3 G = mat3(1.0 / radius);  // world offset → unit sphere
  float extent = radius;         // the longest semi-axis
  spray = 0.0;
  if (draw.ellipsoids != 0u) {
    spray = p.w;
    if (spray == 0.0) {
      const vec4 s0 = draw.shape.v[2u * particle], s1 = draw.shape.v[2u * particle + 1u];
      G = mat3(s0.x, s0.y, s0.z, s0.y, s0.w, s1.x, s0.z, s1.x, s1.y);
      extent = s1.z;
    }
  }
  // The view's rotation is orthonormal: its transpose takes view offsets back to the world.
  to_unit = G * transpose(mat3(view));
  view_centre = (view * vec4(p.xyz, 1.0)).xyz;
  offset = vec3(corner * extent, 0.0);
  const mat4 projection = draw.frame.projection;
  const vec4 on_centre_plane = projection * vec4(view_centre + offset, 1.0);
  const vec4 on_front_plane = projection * vec4(view_centre + vec3(offset.xy, extent), 1.0);
  gl_Position = vec4(on_centre_plane.xy, on_front_plane.z / on_front_plane.w * on_centre_plane.w,
                     on_centre_plane.w);
}

#version 460
#extension GL_GOOGLE_include_directive : require
// SSFR, the ellipsoids (spheres without anisotropy): each pixel's ray through the particle's
// ellipsoid gives the view distance where it enters and the chord inside, into two float
// attachments that the blend units combine, the distance by minimum (the nearest surface) and the
// chord by sum (the water crossed). Spray adds its chord to a third, in particle diameters, and
// leaves the surface alone. Early depth tests against the scene's depth leave out fluid behind
// it; nothing writes depth.
#include "common/frame.glsl"
#include "common/draw_pass.glsl"

layout(early_fragment_tests) in;
layout(location = 0) in vec3 offset;
layout(location = 1) flat in vec3 view_centre;
layout(location = 2) flat in mat3 to_unit;
layout(location = 5) flat in float spray;
layout(location = 0) out float out_distance;
layout(location = 1) out float out_thickness;
layout(location = 2) out float out_spray;

void main() {
  // The ray from the eye through this point of the square, from the square on: near the centre,
  // so the quadratic's terms stay of order one however far the particle is.
  const vec3 direction = normalize(view_centre + offset);
  const vec3 o = to_unit * offset, d = to_unit * direction;
  const float a = dot(d, d), b = dot(o, d), c = dot(o, o) - 1.0;
  const float discriminant = b * b - a * c;
  if (discriminant < 0.0) discard;
  const float root = sqrt(discriminant);
  const float enter = (-b - root) / a, chord = 2.0 * root / a;
  if (spray != 0.0) {
    out_distance = uintBitsToFloat(0x7f800000u);  // +inf: no change
    out_thickness = 0.0;
    out_spray = chord / (2.0 * draw.frame.particle_radius);
    return;
  }
  const vec3 front = view_centre + offset + enter * direction;
  out_distance = max(-front.z, 1e-4);  // looks along −z; never 0: it divides
  out_thickness = chord;
  out_spray = 0.0;
}

// SSFR's particle pass, in compute (ssfr_splat.comp, ssfr_splat_large.comp): each particle's
// ellipsoid (anisotropy.comp's, or a sphere of the particle's radius) is ray-cast at the pixels
// of the rectangle that bounds its bounding sphere's outline, and each pixel keeps the nearest surface's view
// distance (atomicMin of its bits: positive floats order as their bits do), the water crossed and
// the spray crossed (atomicAdd in fixed point, so that the sums do not depend on the order the
// particles come in; ssfr_resolve.comp turns them into floats). Not the rasterizer: on a compute
// GPU (an H100 runs graphics on two of its processing clusters) millions of small squares are
// bound by primitive set-up, which a thread per particle does not pay.
// Mirrored by SplatConstants in core/render/frame_params.h.
#include "common/frame.glsl"
#include "common/dispatch.glsl"

layout(push_constant, std430) uniform Splat {
  Frame frame;
  Vec4s position;   // centres (.w: 1 for spray when `ellipsoids`)
  Vec4s shape;      // two vec4 per particle: the ellipsoid (anisotropy.comp), when `ellipsoids`
  Uints distance;   // per pixel: the nearest surface's view distance, as float bits
  Uints thickness;  // per pixel: the water crossed, kThicknessUnit per count
  Uints spray;      // per pixel: the spray crossed, kSprayUnit particle diameters per count
  Uints large;      // [0]: workgroups for ssfr_splat_large (x, 1, 1), [3]: particles queued,
                    // then from [4] the queued particles
  uint particle_count;
  uint ellipsoids;  // 1 when `position` and `shape` are anisotropy.comp's, else spheres
  uint large_capacity;
} splat;

// 2^-20 m a count: sums reach 4 km of water before a 32-bit count overflows.
const float kThicknessUnit = 1.0 / 1048576.0;
// 2^-16 particle diameters a count.
const float kSprayUnit = 1.0 / 65536.0;
// Particles over more pixels go to ssfr_splat_large, a workgroup each, not one thread's loop.
const uint kInlinePixels = 64u;

struct Particle {
  vec3 view_centre;
  mat3 to_unit;    // a view-space offset → the unit sphere
  bool is_spray;   // adds to the spray, not the surface
  ivec2 first;     // the pixels whose centres the outline's bounds cover, inclusive
  ivec2 last;
};

// The pixel's ray in view space, scaled to reach z = −1 (ssfr_shade.comp's view_position).
vec3 pixel_ray(ivec2 pixel, mat4 projection, vec2 size) {
  const vec2 ndc = (vec2(pixel) + 0.5) / size * 2.0 - 1.0;
  return vec3(ndc.x / projection[0][0], ndc.y / projection[1][1], -1.0);
}

// Where a sphere of radius r, its centre u across and w ahead of the eye (w > r), ends across
// the view, as u/w does at its centre: the slopes of the two lines from the eye that touch it.
vec2 outline_slopes(float u, float w, float r) {
  const float spread = r * sqrt(u * u + w * w - r * r);
  return vec2(u * w - spread, u * w + spread) / (w * w - r * r);
}

// False where nothing of the particle is in view: any of it nearer than the near plane (the whole
// particle is left out, as the rasterizer clipped it) or beyond the far one, or off the frame. Nothing is tested against the
// scene: it is the tank's far side, behind every particle in it.
bool particle_in_view(uint index, out Particle p) {
  const mat4 view = splat.frame.view;
  const mat4 projection = splat.frame.projection;
  const float radius = splat.frame.particle_radius;
  const vec2 size = vec2(splat.frame.width, splat.frame.height);
  const vec4 centre = splat.position.v[index];
  mat3 G = mat3(1.0 / radius);  // world offset → unit sphere
  float extent = radius;         // the longest semi-axis
  p.is_spray = false;
  if (splat.ellipsoids != 0u) {
    p.is_spray = centre.w != 0.0;
    if (!p.is_spray) {
      const vec4 s0 = splat.shape.v[2u * index], s1 = splat.shape.v[2u * index + 1u];
      G = mat3(s0.x, s0.y, s0.z, s0.y, s0.w, s1.x, s0.z, s1.x, s1.y);
      extent = s1.z;
    }
  }
  // The view's rotation is orthonormal: its transpose takes view offsets back to the world.
  p.to_unit = G * transpose(mat3(view));
  p.view_centre = (view * vec4(centre.xyz, 1.0)).xyz;
  const vec4 front = projection * vec4(p.view_centre + vec3(0.0, 0.0, extent), 1.0);
  if (!(front.w > 0.0) || front.z < 0.0 || front.z > front.w) return false;
  // The pixel centres within the outline's bounds, each axis on its own (a sphere off the view's
  // axis projects to an ellipse drawn out away from it).
  const float ahead = -p.view_centre.z;
  const vec2 x = projection[0][0] * outline_slopes(p.view_centre.x, ahead, extent);
  const vec2 y = projection[1][1] * outline_slopes(p.view_centre.y, ahead, extent);
  const vec2 a = (vec2(x.x, y.x) + 1.0) * 0.5 * size - 0.5;
  const vec2 b = (vec2(x.y, y.y) + 1.0) * 0.5 * size - 0.5;
  p.first = max(ivec2(ceil(min(a, b))), ivec2(0));
  p.last = min(ivec2(floor(max(a, b))), ivec2(size) - 1);
  return all(lessThanEqual(p.first, p.last));
}

uint pixels_of(Particle p) {
  const uvec2 span = uvec2(p.last - p.first + 1);
  return span.x * span.y;
}

// The ray through the pixel's centre, from where it crosses the plane of the particle's centre
// (near the centre, so that the quadratic's terms stay of order one however far the particle
// is), against the ellipsoid.
void splat_pixel(Particle p, ivec2 pixel) {
  const vec3 ray = pixel_ray(pixel, splat.frame.projection,
                             vec2(splat.frame.width, splat.frame.height));
  const vec3 on_plane = ray * -p.view_centre.z;
  const vec3 direction = normalize(on_plane);
  const vec3 o = p.to_unit * (on_plane - p.view_centre), d = p.to_unit * direction;
  const float a = dot(d, d), b = dot(o, d), c = dot(o, o) - 1.0;
  const float discriminant = b * b - a * c;
  if (discriminant < 0.0) return;
  const float root = sqrt(discriminant);
  const float enter = (-b - root) / a, chord = 2.0 * root / a;
  const uint at = uint(pixel.y) * splat.frame.width + uint(pixel.x);
  if (p.is_spray) {
    const float diameters = chord / (2.0 * splat.frame.particle_radius);
    atomicAdd(splat.spray.v[at], uint(diameters / kSprayUnit + 0.5));
    return;
  }
  const vec3 front = on_plane + enter * direction;
  const float distance = max(-front.z, 1e-4);  // looks along −z; never 0: it divides
  atomicMin(splat.distance.v[at], floatBitsToUint(distance));
  atomicAdd(splat.thickness.v[at], uint(chord / kThicknessUnit + 0.5));
}

// The particle's pixels one after the other, from the `from`-th in steps of `step`.
void splat_pixels(Particle p, uint from, uint step) {
  const uint columns = uint(p.last.x - p.first.x + 1);
  const uint count = pixels_of(p);
  for (uint k = from; k < count; k += step) {
    splat_pixel(p, p.first + ivec2(k % columns, k / columns));
  }
}

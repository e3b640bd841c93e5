// The particle passes, in compute (particle_splat.comp, particle_splat_large.comp): each particle
// is cast at the pixels of a rectangle that bounds it, one way per mode.
// - SSFR: its ellipsoid (anisotropy.comp's, or a sphere of the particle's radius) is ray-cast,
//   and each pixel keeps the nearest surface's view distance (atomicMin of its bits: positive
//   floats order as their bits do), the water crossed and the spray crossed (atomicAdd in fixed
//   point, so that the sums do not depend on the order the particles come in; ssfr_resolve.comp
//   turns them into floats).
// - Points: a lit sphere impostor, a disc in the plane of the particle's centre facing the
//   camera with a sphere's normals and depths; a first pass keeps each pixel's nearest distance,
//   a second writes the colour of the particle that has it.
// Not the rasterizer: on a compute GPU (an H100 runs graphics on two of its processing clusters)
// millions of small squares are bound by primitive set-up, which a thread per particle does not
// pay. Nothing is tested against the scene: it is the tank's far side, behind every particle in
// it. Mirrored by SplatConstants in core/render/frame_params.h.
#include "common/frame.glsl"
#include "common/dispatch.glsl"

const uint kSsfr = 0u, kPointsDistance = 1u, kPointsColour = 2u;

layout(push_constant, std430) uniform Splat {
  Frame frame;
  Vec4s position;       // centres (.w, SSFR with `ellipsoids`: 1 for spray)
  Vec4s velocity;       // points: coloured by speed
  Floats density_ratio; // points: or by ρ/ρ0 (frame.colour_by_density)
  Vec4s shape;          // SSFR with `ellipsoids`: two vec4 per particle (anisotropy.comp)
  Uints distance;       // per pixel: the nearest surface's view distance, as float bits
  Uints thickness;      // SSFR, per pixel: the water crossed, kThicknessUnit per count
  Uints spray;          // SSFR, per pixel: the spray crossed, kSprayUnit diameters per count
  Uints image;          // points, per pixel: RGBA8, the scene's where no particle is
  Uints large;          // [0]: workgroups for particle_splat_large (x, 1, 1), [3]: particles
                        // queued, then from [4] the queued particles
  uint particle_count;
  uint ellipsoids;      // SSFR: 1 when `position` and `shape` are anisotropy.comp's
  uint large_capacity;
  uint mode;            // kSsfr, kPointsDistance or kPointsColour
} splat;

// 2^-20 m a count: sums reach 4 km of water before a 32-bit count overflows.
const float kThicknessUnit = 1.0 / 1048576.0;
// 2^-16 particle diameters a count.
const float kSprayUnit = 1.0 / 65536.0;
// Particles over more pixels go to particle_splat_large, a workgroup each, not one thread's loop.
const uint kInlinePixels = 64u;

// What a particle's pixels need, loaded once: through buffer references each pixel would load
// it again.
struct Particle {
  vec2 size;            // the frame's, in pixels
  vec2 projection_xy;   // projection[0][0] and [1][1]
  float radius;         // the particles'
  vec3 view_centre;
  mat3 to_unit;    // SSFR: a view-space offset → the unit sphere
  bool is_spray;   // SSFR: adds to the spray, not the surface
  vec3 colour;     // points
  ivec2 first;     // the pixels whose centres the bounds cover, inclusive
  ivec2 last;
};

// The pixel's ray in view space, scaled to reach z = −1 (ssfr_shade.comp's view_position).
// Precise, as all that the points' distance is made of: their second pass finds the particle that
// won the first by comparing bits, and the two passes' pipelines must not round differently.
vec3 pixel_ray(Particle p, ivec2 pixel) {
  precise const vec2 ndc = (vec2(pixel) + 0.5) / p.size * 2.0 - 1.0;
  precise const vec3 ray = vec3(ndc / p.projection_xy, -1.0);
  return ray;
}

// Where a sphere of radius r, its centre u across and w ahead of the eye (w > r), ends across
// the view, as u/w does at its centre: the slopes of the two lines from the eye that touch it.
vec2 outline_slopes(float u, float w, float r) {
  const float spread = r * sqrt(u * u + w * w - r * r);
  return vec2(u * w - spread, u * w + spread) / (w * w - r * r);
}

vec3 points_colour(uint index) {
  float blend;
  if (splat.frame.colour_by_density != 0u) {
    const float span = splat.frame.density_span;
    blend = clamp((splat.density_ratio.v[index] - (1.0 - span)) / (2.0 * span), 0.0, 1.0);
  } else {
    blend = clamp(length(splat.velocity.v[index].xyz) / splat.frame.full_speed, 0.0, 1.0);
  }
  const vec4 slow = splat.frame.slow_colour, fast = splat.frame.fast_colour;
  return mix(slow.rgb, fast.rgb, blend);
}

// False where nothing of the particle is in view: any of it nearer than the near plane (the whole
// particle is left out, as a rasterizer would clip it) or beyond the far one, or off the frame.
bool particle_in_view(uint index, out Particle p) {
  const mat4 view = splat.frame.view;
  const mat4 projection = splat.frame.projection;
  const float radius = splat.frame.particle_radius;
  const vec2 size = vec2(splat.frame.width, splat.frame.height);
  p.size = size;
  p.projection_xy = vec2(projection[0][0], projection[1][1]);
  p.radius = radius;
  const vec4 centre = splat.position.v[index];
  mat3 G = mat3(1.0 / radius);  // world offset → unit sphere
  float extent = radius;         // the longest semi-axis
  p.is_spray = false;
  if (splat.mode == kSsfr && splat.ellipsoids != 0u) {
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
  p.colour = splat.mode == kPointsColour ? points_colour(index) : vec3(0.0);
  const vec4 front = projection * vec4(p.view_centre + vec3(0.0, 0.0, extent), 1.0);
  if (!(front.w > 0.0) || front.z < 0.0 || front.z > front.w) return false;
  vec2 a, b;  // opposite corners of the bounds, in pixels
  if (splat.mode == kSsfr) {
    // The outline of the bounding sphere, each axis on its own (a sphere off the view's axis
    // projects to an ellipse drawn out away from it).
    const float ahead = -p.view_centre.z;
    const vec2 x = projection[0][0] * outline_slopes(p.view_centre.x, ahead, extent);
    const vec2 y = projection[1][1] * outline_slopes(p.view_centre.y, ahead, extent);
    a = (vec2(x.x, y.x) + 1.0) * 0.5 * size - 0.5;
    b = (vec2(x.y, y.y) + 1.0) * 0.5 * size - 0.5;
  } else {  // the impostor's square, in the plane of the centre
    const vec4 low = projection * vec4(p.view_centre + vec3(-extent, -extent, 0.0), 1.0);
    const vec4 high = projection * vec4(p.view_centre + vec3(extent, extent, 0.0), 1.0);
    a = (low.xy / low.w + 1.0) * 0.5 * size - 0.5;
    b = (high.xy / high.w + 1.0) * 0.5 * size - 0.5;
  }
  if (any(isnan(a)) || any(isnan(b))) return false;
  // Clamped as floats: a float beyond an int's range has no defined conversion.
  p.first = ivec2(clamp(ceil(min(a, b)), vec2(0.0), size));
  p.last = ivec2(clamp(floor(max(a, b)), vec2(-1.0), size - 1.0));
  return all(lessThanEqual(p.first, p.last));
}

uint pixels_of(Particle p) {
  const uvec2 span = uvec2(p.last - p.first + 1);
  return span.x * span.y;
}

// SSFR: the ray through the pixel's centre, from where it crosses the plane of the particle's
// centre (near the centre, so that the quadratic's terms stay of order one however far the
// particle is), against the ellipsoid.
void cast_ellipsoid(Particle p, uint at, vec3 on_plane) {
  const vec3 direction = normalize(on_plane);
  const vec3 o = p.to_unit * (on_plane - p.view_centre), d = p.to_unit * direction;
  const float a = dot(d, d), b = dot(o, d), c = dot(o, o) - 1.0;
  const float discriminant = b * b - a * c;
  if (discriminant < 0.0) return;
  const float root = sqrt(discriminant);
  const float enter = (-b - root) / a, chord = 2.0 * root / a;
  if (p.is_spray) {
    const float diameters = chord / (2.0 * p.radius);
    atomicAdd(splat.spray.v[at], uint(diameters / kSprayUnit + 0.5));
    return;
  }
  const vec3 front = on_plane + enter * direction;
  const float distance = max(-front.z, 1e-4);  // looks along −z; never 0: it divides
  atomicMin(splat.distance.v[at], floatBitsToUint(distance));
  atomicAdd(splat.thickness.v[at], uint(chord / kThicknessUnit + 0.5));
}

// Points: the impostor's disc where the pixel's ray crosses the centre's plane, its depth and
// light a sphere's.
void cast_impostor(Particle p, uint at, vec3 on_plane) {
  precise const vec2 across = (on_plane.xy - p.view_centre.xy) / p.radius;
  precise const float r2 = dot(across, across);
  if (r2 > 1.0) return;
  precise const vec3 normal = vec3(across, sqrt(1.0 - r2));
  precise const float distance = -(p.view_centre.z + normal.z * p.radius);
  if (splat.mode == kPointsDistance) {
    atomicMin(splat.distance.v[at], floatBitsToUint(distance));
  } else if (splat.distance.v[at] == floatBitsToUint(distance)) {
    const vec4 light = splat.frame.light_direction;
    const float diffuse = max(dot(normal, normalize(light.xyz)), 0.0);
    splat.image.v[at] = packUnorm4x8(vec4(p.colour * (0.3 + 0.7 * diffuse), 1.0));
  }
}

// The particle's pixels one after the other, from the `from`-th in steps of `step`.
void splat_pixels(Particle p, uint from, uint step) {
  const uint columns = uint(p.last.x - p.first.x + 1);
  const uint count = pixels_of(p);
  const uint width = uint(p.size.x);
  for (uint k = from; k < count; k += step) {
    const ivec2 pixel = p.first + ivec2(k % columns, k / columns);
    const uint at = uint(pixel.y) * width + uint(pixel.x);
    precise const vec3 on_plane = pixel_ray(p, pixel) * -p.view_centre.z;
    if (splat.mode == kSsfr) {
      cast_ellipsoid(p, at, on_plane);
    } else {
      cast_impostor(p, at, on_plane);
    }
  }
}

#version 460
#extension GL_GOOGLE_include_directive : require
// SSFR, depth smoothing: one direction of a separable filter. The radius is a length in the
// scene, so it covers fewer pixels far away (view-invariant, as the talk recommends).
//   bilateral (van der Laan et al. 2009): a range weight keeps silhouettes sharp.
//   narrow range (Truong & Yuksel 2018): only depths within a narrow range around the centre
//   count; a sample pair (±k) with either member in front of the range is dropped whole, so the
//   kernel stays symmetric (their bias correction); samples far behind, background included,
//   are clamped to just behind the centre so silhouettes round off; and the range widens with
//   every accepted pair (their dynamic range), so slopes smooth without reaching across gaps.
#include "common/frame.glsl"
#include "common/screen_pass.glsl"

// Pixels without fluid hold +infinity (the depth buffer is cleared to its bits).
float infinity() { return uintBitsToFloat(0x7f800000u); }

float depth_at(ivec2 q) {
  return screen.depth_in.v[uint(q.y) * screen.frame.width + uint(q.x)];
}

bool inside(ivec2 q) {
  return q.x >= 0 && q.y >= 0 && q.x < int(screen.frame.width) && q.y < int(screen.frame.height);
}

float gaussian(int k, float sigma) { return exp(-float(k * k) / (2.0 * sigma * sigma)); }

float bilateral(ivec2 p, ivec2 step, float centre, int radius, float sigma) {
  const float falloff = screen.frame.depth_falloff;
  float sum = centre, weights = 1.0;
  for (int k = -radius; k <= radius; ++k) {
    const ivec2 q = p + k * step;
    if (k == 0 || !inside(q)) continue;
    const float d = depth_at(q);
    if (d == infinity()) continue;
    const float difference = (d - centre) / falloff;
    const float weight = gaussian(k, sigma) * exp(-difference * difference);
    sum += d * weight;
    weights += weight;
  }
  return sum / weights;
}

float narrow_range(ivec2 p, ivec2 step, float centre, int radius, float sigma) {
  const float threshold = screen.frame.depth_falloff;
  const float clamped_behind = centre + screen.frame.particle_radius;
  float low = centre - threshold, high = centre + threshold;
  float sum = centre, weights = 1.0;
  for (int k = 1; k <= radius; ++k) {
    const ivec2 before = p - k * step, after = p + k * step;
    if (!inside(before) || !inside(after)) break;
    vec2 pair = vec2(depth_at(before), depth_at(after));
    if (any(lessThan(pair, vec2(low)))) continue;
    pair = mix(pair, vec2(clamped_behind), greaterThan(pair, vec2(high)));
    low = min(low, min(pair.x, pair.y) - threshold);
    high = max(high, max(pair.x, pair.y) + threshold);
    const float weight = gaussian(k, sigma);
    sum += (pair.x + pair.y) * weight;
    weights += 2.0 * weight;
  }
  return sum / weights;
}

void main() {
  const uint width = screen.frame.width, height = screen.frame.height;
  const uint index = invocation();  // one per pixel, rows one after the other
  if (index >= width * height) return;
  const ivec2 p = ivec2(index % width, index / width);
  const float centre = screen.depth_in.v[index];
  if (centre == infinity()) {
    screen.depth_out.v[index] = infinity();
    return;
  }
  const float pixels_per_metre =
      0.5 * float(height) * abs(screen.frame.projection[1][1]) / centre;
  const int radius = clamp(int(screen.frame.smoothing_radius * pixels_per_metre), 1, 24);
  const float sigma = max(float(radius) * 0.5, 0.5);
  const ivec2 step = screen.axis == 0u ? ivec2(1, 0) : ivec2(0, 1);
  screen.depth_out.v[index] = screen.narrow_range != 0u
                                  ? narrow_range(p, step, centre, radius, sigma)
                                  : bilateral(p, step, centre, radius, sigma);
}

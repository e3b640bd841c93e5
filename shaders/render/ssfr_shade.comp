#version 460
#extension GL_GOOGLE_include_directive : require
// SSFR, shading: normals from the smoothed depth, Fresnel reflection of the sky, refraction of the
// scene behind with Beer–Lambert absorption by thickness, and a specular highlight; then spray
// over it, white and matte, as dense as the spray the pixel's ray crossed.
#include "common/frame.glsl"
#include "common/screen_pass.glsl"
#include "common/scene.glsl"

// Pixels without fluid hold +infinity (the depth buffer is cleared to its bits).
float infinity() { return uintBitsToFloat(0x7f800000u); }

vec3 view_position(vec2 pixel, float distance, mat4 projection, uint width, uint height) {
  const vec2 ndc = (pixel + 0.5) / vec2(width, height) * 2.0 - 1.0;
  return distance * vec3(ndc.x / projection[0][0], ndc.y / projection[1][1], -1.0);
}

float depth_at(ivec2 q, uint width, uint height) {
  if (q.x < 0 || q.y < 0 || q.x >= int(width) || q.y >= int(height)) return infinity();
  return screen.depth_in.v[uint(q.y) * width + uint(q.x)];
}

const vec3 kSprayColour = vec3(0.88, 0.92, 0.95);

// The water's colour at pixel p, whose smoothed surface lies at view distance d.
vec3 water(ivec2 p, float d, uint width, uint height) {
  const uint index = uint(p.y) * width + uint(p.x);
  const mat4 projection = screen.frame.projection;
  const vec3 position = view_position(vec2(p), d, projection, width, height);
  // Normal from the smaller of the two one-sided differences on each axis (silhouettes).
  vec3 dx = vec3(0.0), dy = vec3(0.0);
  {
    const float right = depth_at(p + ivec2(1, 0), width, height);
    const float left = depth_at(p - ivec2(1, 0), width, height);
    const vec3 to_right = view_position(vec2(p + ivec2(1, 0)), right, projection, width, height) - position;
    const vec3 from_left = position - view_position(vec2(p - ivec2(1, 0)), left, projection, width, height);
    dx = (left == infinity() || (right != infinity() && abs(to_right.z) < abs(from_left.z))) ? to_right : from_left;
    const float down = depth_at(p + ivec2(0, 1), width, height);
    const float up = depth_at(p - ivec2(0, 1), width, height);
    const vec3 to_down = view_position(vec2(p + ivec2(0, 1)), down, projection, width, height) - position;
    const vec3 from_up = position - view_position(vec2(p - ivec2(0, 1)), up, projection, width, height);
    dy = (up == infinity() || (down != infinity() && abs(to_down.z) < abs(from_up.z))) ? to_down : from_up;
  }
  vec3 normal = normalize(cross(dy, dx));
  if (!(dot(normal, normal) > 0.5)) normal = vec3(0.0, 0.0, 1.0);
  if (normal.z < 0.0) normal = -normal;
  const vec3 to_eye = normalize(-position);

  // Signed: the mesh sums back minus front faces; a shortfall anywhere must not go negative.
  const float thickness = max(screen.thickness.v[index], 0.0);
  // Refraction: the scene behind, displaced along the normal, dimmed by the water crossed.
  // A few per cent of the frame for a few centimetres of water.
  const vec2 offset = normal.xy * min(thickness, 0.1) * 0.4 * float(height);
  const ivec2 behind = clamp(p + ivec2(offset.x, -offset.y), ivec2(0), ivec2(width - 1, height - 1));
  const vec3 background = unpackUnorm4x8(screen.scene.v[uint(behind.y) * width + uint(behind.x)]).rgb;
  const vec4 absorption = screen.frame.absorption;
  const vec3 refracted = background * exp(-absorption.rgb * thickness);
  // Reflection of the sky, weighted by Schlick's Fresnel term (water: F0 = 0.02).
  const mat4 inverse_view = screen.frame.inverse_view;
  const vec3 reflected_direction = mat3(inverse_view) * reflect(-to_eye, normal);
  const float cosine = max(dot(normal, to_eye), 0.0);
  const float fresnel = 0.02 + 0.98 * pow(1.0 - cosine, 5.0);
  vec3 colour = mix(refracted, sky(reflected_direction), fresnel);
  const vec4 light = screen.frame.light_direction;
  const vec3 halfway = normalize(normalize(light.xyz) + to_eye);
  colour += vec3(pow(max(dot(normal, halfway), 0.0), 120.0)) * 0.8;
  return clamp(colour, 0.0, 1.0);
}

void main() {
  const uint width = screen.frame.width, height = screen.frame.height;
  const uint index = invocation();  // one per pixel, rows one after the other
  if (index >= width * height) return;
  const ivec2 p = ivec2(index % width, index / width);
  const float d = screen.depth_in.v[index];
  const vec3 colour = d == infinity() ? unpackUnorm4x8(screen.scene.v[index]).rgb
                                      : water(p, d, width, height);
  // A particle diameter of spray hides about half of what is behind it.
  const float foam = 1.0 - exp(-0.7 * screen.spray.v[index]);
  screen.image.v[index] = packUnorm4x8(vec4(mix(colour, kSprayColour, foam), 1.0));
}


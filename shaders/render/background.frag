#version 460
#extension GL_GOOGLE_include_directive : require
// The scene around the fluid, ray-cast per pixel so that it needs no meshes: the tank's far
// walls (glass with a faint 10 cm grid) and its tiled floor, a larger floor outside it, and a
// sky.
#include "common/frame.glsl"
#include "common/draw_pass.glsl"
#include "common/scene.glsl"

layout(location = 0) in vec2 ndc;
layout(location = 0) out vec4 colour;


float grid_line(vec2 p, float spacing, float width) {
  const vec2 f = abs(fract(p / spacing + 0.5) - 0.5) * spacing;
  return 1.0 - smoothstep(0.0, width, min(f.x, f.y));
}

void main() {
  const mat4 projection = draw.frame.projection;
  const mat4 inverse_view = draw.frame.inverse_view;
  const vec4 tank_min = draw.frame.tank_min, tank_max = draw.frame.tank_max;
  const vec3 eye = inverse_view[3].xyz;
  const vec3 view_ray = vec3(ndc.x / projection[0][0], ndc.y / projection[1][1], -1.0);
  const vec3 ray = normalize(mat3(inverse_view) * view_ray);

  // Where the ray leaves the tank: its far wall or floor, seen through the near glass.
  const vec3 inverse_ray = 1.0 / ray;
  const vec3 t0 = (tank_min.xyz - eye) * inverse_ray, t1 = (tank_max.xyz - eye) * inverse_ray;
  const vec3 t_near = min(t0, t1), t_far = max(t0, t1);
  const float enter = max(max(t_near.x, t_near.y), t_near.z);
  const float leave = min(min(t_far.x, t_far.y), t_far.z);
  vec3 shade;
  if (leave > max(enter, 0.0)) {
    const vec3 p = eye + leave * ray;
    if (abs(p.y - tank_min.y) < 1e-4 * (1.0 + leave)) {  // the tank's floor: light tiles
      const vec2 tile = floor(p.xz / 0.1);
      const float checker = mod(tile.x + tile.y, 2.0);
      shade = mix(vec3(0.80, 0.78, 0.72), vec3(0.55, 0.52, 0.48), checker);
    } else {  // a wall: pale glass with a grid
      const vec3 local = p - tank_min.xyz;
      const float line = max(grid_line(local.xy, 0.1, 0.002), grid_line(local.zy, 0.1, 0.002));
      shade = mix(vec3(0.70, 0.80, 0.86), vec3(0.35, 0.45, 0.55), line);
    }
  } else if (ray.y < 0.0) {  // the room's floor, below the tank
    const float t = (tank_min.y - 0.001 - eye.y) / ray.y;
    const vec3 p = eye + t * ray;
    const vec2 tile = floor(p.xz / 0.5);
    const float fade = exp(-0.05 * t);
    shade = mix(sky(ray), mix(vec3(0.30), vec3(0.22), mod(tile.x + tile.y, 2.0)), fade);
  } else {
    shade = sky(ray);
  }
  colour = vec4(shade, 1.0);
}

#version 460
#extension GL_GOOGLE_include_directive : require
// Marching Cubes, step 1: each particle adds its kernel weight (1 − r²/R²)³ to the grid nodes
// within R (integer atomics).
#include "common/core.glsl"
#include "common/mc_pass.glsl"

void main() {
  const uint i = invocation();
  const ivec4 nodes = pass.nodes;
  if (i >= uint(nodes.w)) return;
  const vec4 origin = pass.origin;
  const vec4 p = pass.position.v[i];
  const vec3 local = (p.xyz - origin.xyz) / origin.w;
  const float radius = pass.radius, r2 = radius * radius;
  const int reach = int(ceil(radius / origin.w));
  const ivec3 centre = ivec3(floor(local));
  for (int z = max(centre.z - reach, 0); z <= min(centre.z + reach + 1, nodes.z - 1); ++z) {
    for (int y = max(centre.y - reach, 0); y <= min(centre.y + reach + 1, nodes.y - 1); ++y) {
      for (int x = max(centre.x - reach, 0); x <= min(centre.x + reach + 1, nodes.x - 1); ++x) {
        const vec3 d = (vec3(x, y, z) - local) * origin.w;
        const float q = 1.0 - dot(d, d) / r2;
        if (q <= 0.0) continue;
        atomicAdd(pass.field.v[node_index(ivec3(x, y, z))], uint(q * q * q / kFieldUnit));
      }
    }
  }
}

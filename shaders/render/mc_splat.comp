#version 460
#extension GL_GOOGLE_include_directive : require
// Marching Cubes, field step 1: each particle spreads its share of a node at rest over the 8
// nodes of its cell (trilinear, integer atomics; a node of fluid at rest sums to 1/kSplatUnit,
// so the sum overflows only past 65536 times the rest density, at any grid spacing). The blur passes then make it smooth; 8 atomics per particle
// instead of a whole kernel's worth keeps the field cheap where atomics are slow (CPUs).
#include "common/core.glsl"
#include "common/mc_pass.glsl"

void main() {
  const uint i = invocation();
  const ivec4 nodes = pass.nodes;
  if (i >= uint(nodes.w)) return;
  const vec4 origin = pass.origin;
  const vec4 p = pass.position.v[i];
  // The margin keeps particles in the tank well inside the grid; a stray (or a NaN after a
  // blow-up) adds nothing rather than piling onto the grid's edge.
  const vec3 local = (p.xyz - origin.xyz) / origin.w;
  if (!(all(greaterThanEqual(local, vec3(0.0))) && all(lessThan(local, vec3(nodes.xyz - 1))))) {
    return;
  }
  const ivec3 base = clamp(ivec3(floor(local)), ivec3(0), nodes.xyz - 2);
  const vec3 f = local - vec3(base);
  const float scale = pass.inverse_rest / kSplatUnit;
  for (int corner = 0; corner < 8; ++corner) {
    const ivec3 offset = ivec3(corner & 1, (corner >> 1) & 1, corner >> 2);
    const vec3 w3 = mix(1.0 - f, f, vec3(offset));
    const uint weight = uint(w3.x * w3.y * w3.z * scale + 0.5);
    if (weight != 0u) atomicAdd(pass.splat.v[node_index(base + offset)], weight);
  }
}

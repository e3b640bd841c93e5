// Push constants of the Marching Cubes compute passes; mirrored by McConstants in
// core/render/marching_cubes.h. Included after common/core.glsl.
layout(buffer_reference, std430, buffer_reference_align = 4) buffer Ints { int v[]; };

layout(push_constant, std430) uniform McPass {
  Vec4s position;   // the particles (w unused)
  Uints field;      // per node: Σ kernel weight, in 1/kFieldUnit
  Ints tables;      // 256 × 16 edges (−1 ends a case), then 256 triangle counts
  Vec4s vertices;   // out: per vertex, position then normal
  Uints draw;       // VkDrawIndirectCommand; vertexCount counts the vertices written
  vec4 origin;      // xyz: node (0,0,0), m; w: node spacing, m
  ivec4 nodes;      // xyz: nodes per axis; w: particles
  float radius;     // of a particle's contribution to the field, m
  float inverse_rest_sum;  // 1 / the field's value inside fluid at rest
  float threshold;  // the surface: where the normalised field crosses it
  uint max_vertices;
} pass;

const float kFieldUnit = 1.0 / 1024.0;

// Vectors loaded whole (lavapipe reads single components of some as 0; see sim_kernels.glsl).
uint node_index(ivec3 p) {
  const ivec4 nodes = pass.nodes;
  return uint(p.x + nodes.x * (p.y + nodes.y * p.z));
}

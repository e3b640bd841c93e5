// Push constants of the Marching Cubes compute passes; mirrored by McConstants in
// core/render/marching_cubes.h. Included after common/core.glsl.
layout(buffer_reference, std430, buffer_reference_align = 4) buffer Ints { int v[]; };

layout(push_constant, std430) uniform McPass {
  Vec4s position;   // the particles (w unused)
  Uints splat;      // per node: Σ trilinear weights × inverse_rest of the particles around it,
                    // in kSplatUnit
  Floats blur_in;   // the blur pass's input (the x pass reads `splat` instead)
  Floats blur_out;  // and output
  Floats field;     // per node: the finished field, 1 inside fluid at rest
  Ints tables;      // 256 × 16 edges (−1 ends a case), then 256 triangle counts
  Vec4s vertices;   // out: per vertex, position then normal
  Uints draw;       // VkDrawIndirectCommand; vertexCount counts the vertices written
  vec4 origin;      // xyz: node (0,0,0), m; w: node spacing, m
  ivec4 nodes;      // xyz: nodes per axis; w: particles
  int axis;         // of this blur pass: 0 x (from `splat`), 1 y, 2 z
  float inverse_rest;  // 1 / a node's splat sum inside fluid at rest
  float threshold;  // the surface: where the field crosses it
  uint max_vertices;
} pass;

const float kSplatUnit = 1.0 / 65536.0;

// Vectors loaded whole (lavapipe reads single components of some as 0; see sim_kernels.glsl).
uint node_index(ivec3 p) {
  const ivec4 nodes = pass.nodes;
  return uint(p.x + nodes.x * (p.y + nodes.y * p.z));
}

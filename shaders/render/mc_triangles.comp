#version 460
#extension GL_GOOGLE_include_directive : require
// Marching Cubes, step 2: each cell looks up its case and appends its triangles (positions on the
// crossed edges, normals from the field's gradient) to the vertex buffer.
#include "common/core.glsl"
#include "common/mc_pass.glsl"

const ivec3 kCorners[8] = ivec3[](ivec3(0, 0, 0), ivec3(1, 0, 0), ivec3(1, 1, 0), ivec3(0, 1, 0),
                                  ivec3(0, 0, 1), ivec3(1, 0, 1), ivec3(1, 1, 1), ivec3(0, 1, 1));
const ivec2 kEdges[12] = ivec2[](ivec2(0, 1), ivec2(1, 2), ivec2(2, 3), ivec2(3, 0), ivec2(4, 5),
                                 ivec2(5, 6), ivec2(6, 7), ivec2(7, 4), ivec2(0, 4), ivec2(1, 5),
                                 ivec2(2, 6), ivec2(3, 7));

float field_at(ivec3 p) {
  const ivec4 nodes = pass.nodes;
  p = clamp(p, ivec3(0), nodes.xyz - 1);
  return pass.field.v[node_index(p)];
}

vec3 gradient_at(ivec3 p) {
  return vec3(field_at(p + ivec3(1, 0, 0)) - field_at(p - ivec3(1, 0, 0)),
              field_at(p + ivec3(0, 1, 0)) - field_at(p - ivec3(0, 1, 0)),
              field_at(p + ivec3(0, 0, 1)) - field_at(p - ivec3(0, 0, 1)));
}

void main() {
  const ivec4 nodes = pass.nodes;
  const ivec3 cells = nodes.xyz - 1;
  const uint index = invocation();
  if (index >= uint(cells.x * cells.y * cells.z)) return;
  const ivec3 cell = ivec3(int(index) % cells.x, (int(index) / cells.x) % cells.y,
                           int(index) / (cells.x * cells.y));
  const float threshold = pass.threshold;
  float values[8];
  int pattern = 0;
  for (int c = 0; c < 8; ++c) {
    values[c] = field_at(cell + kCorners[c]);
    if (values[c] > threshold) pattern |= 1 << c;
  }
  const int triangles = pass.tables.v[256 * 16 + pattern];
  if (triangles == 0) return;
  const uint count = uint(3 * triangles);
  const uint first = atomicAdd(pass.draw.v[0], count);
  const vec4 origin = pass.origin;
  if (first + count > pass.max_vertices) {
    // The buffer is full and the draw is clamped to it: fill the part of it that is this cell's
    // with degenerate triangles, which cover no pixel.
    for (uint k = first; k < pass.max_vertices; ++k) {
      pass.vertices.v[2 * k] = vec4(origin.xyz, 1.0);
      pass.vertices.v[2 * k + 1] = vec4(0.0, 1.0, 0.0, 0.0);
    }
    return;
  }
  for (uint k = 0; k < count; ++k) {
    ivec2 edge = kEdges[pass.tables.v[pattern * 16 + int(k)]];
    // From the lower node to the higher, so that the cells sharing a grid edge compute the very
    // same point (a watertight mesh, bit for bit).
    const ivec3 ca = kCorners[edge.x], cb = kCorners[edge.y];
    if (ca.x + ca.y + ca.z > cb.x + cb.y + cb.z) edge = edge.yx;
    const float va = values[edge.x], vb = values[edge.y];
    const float t = clamp((threshold - va) / (vb - va), 0.0, 1.0);
    const ivec3 a = cell + kCorners[edge.x], b = cell + kCorners[edge.y];
    const vec3 position = origin.xyz + origin.w * mix(vec3(a), vec3(b), t);
    // Outward: down the field's gradient.
    vec3 normal = -mix(gradient_at(a), gradient_at(b), t);
    normal = dot(normal, normal) > 1e-20 ? normalize(normal) : vec3(0, 1, 0);
    pass.vertices.v[2 * (first + k)] = vec4(position, 1.0);
    pass.vertices.v[2 * (first + k) + 1] = vec4(normal, 0.0);
  }
}

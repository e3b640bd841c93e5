// Marching Cubes on the GPU (Lorensen & Cline 1987), for small counts and near views: a density
// field splatted from the particles onto a grid over the tank, then per cell the case table's
// triangles, with normals from the field's gradient, appended to a vertex buffer whose size the
// GPU writes into an indirect draw. Nothing returns to the host.
#pragma once

#include "fluidcast/gpu/buffer.h"
#include "fluidcast/gpu/command_slot.h"
#include "fluidcast/gpu/compute_pipeline.h"
#include "fluidcast/render/frame_renderer.h"

namespace fluidcast::render {

// Mirrors shaders/common/mc_pass.glsl.
struct McConstants {
  VkDeviceAddress position, field, tables, vertices, draw;
  alignas(16) glm::vec4 origin;  // w: node spacing
  glm::ivec4 nodes;              // w: particles
  float radius;
  float inverse_rest_sum;
  float threshold;
  std::uint32_t max_vertices;
};
static_assert(offsetof(McConstants, origin) == 48 && offsetof(McConstants, radius) == 80);

class MarchingCubes {
 public:
  // A grid of `resolution` nodes along the tank's longest side (and as fine on the others), with
  // a layer of nodes outside so the surface closes; the field of particles of `radius`.
  MarchingCubes(gpu::Context& context, const sim::Box& tank, int resolution, float particle_radius);

  bool fits(const sim::Box& tank, int resolution, float particle_radius) const;
  // Records the field and triangle passes; afterwards vertices() and draw_buffer() are ready for
  // the vertex shader and vkCmdDrawIndirect.
  // Marks `timestamps` after the field and after the triangles (two marks).
  void record(VkCommandBuffer commands, const ParticleView& particles, float threshold,
              gpu::TimestampQueries& timestamps) const;
  VkDeviceAddress vertices() const { return vertices_.address(); }
  VkBuffer draw_buffer() const { return draw_.get(); }
  glm::ivec3 nodes() const { return nodes_; }

 private:
  sim::Box tank_;
  int resolution_;
  float particle_radius_;
  glm::vec3 origin_;
  float spacing_;
  glm::ivec3 nodes_;
  float field_radius_, inverse_rest_sum_;
  std::uint32_t max_vertices_;
  gpu::ComputePipeline field_pass_, triangles_pass_, clamp_pass_;
  gpu::Buffer tables_, field_, vertices_, draw_;
};

}  // namespace fluidcast::render

// Marching Cubes on the GPU (Lorensen & Cline 1987), for small counts and near views: a density
// field over a grid around the tank — each particle splats onto its cell's 8 nodes, then a
// separable Gaussian blur (three passes, no atomics) — then per cell the case table's triangles,
// with normals from the field's gradient, appended to a vertex buffer whose size the GPU writes
// into an indirect draw. Nothing returns to the host.
#pragma once

#include "fluidcast/gpu/buffer.h"
#include "fluidcast/gpu/command_slot.h"
#include "fluidcast/gpu/compute_pipeline.h"
#include "fluidcast/render/frame_renderer.h"

namespace fluidcast::render {

// Mirrors shaders/common/mc_pass.glsl.
struct McConstants {
  VkDeviceAddress position, splat, blur_in, blur_out, field, tables, vertices, draw;
  glm::vec4 origin;  // w: node spacing
  glm::ivec4 nodes;  // w: particles
  std::int32_t axis;
  float inverse_rest;
  float threshold;
  std::uint32_t max_vertices;
};
// Within the 128 bytes of push constants every device has.
static_assert(offsetof(McConstants, origin) == 64 && offsetof(McConstants, axis) == 96 &&
              offsetof(McConstants, max_vertices) == 108 && sizeof(McConstants) <= 128);

class MarchingCubes {
 public:
  // A grid of `resolution` nodes along the tank's longest side (and as fine on the others), with
  // a layer of nodes outside so the surface closes; the field of particles of `radius`.
  // The blur's σ: kSigmaRadii particle radii (about the width of the kernel Müller et al. use for
  // surfaces), within kMinSigmaNodes (else the trilinear splat shows) and kMaxSigmaNodes node
  // spacings (the blur's 16 taps a side: grids much finer than the particles get a narrower
  // blur, and a bumpier surface).
  static constexpr float kSigmaRadii = 1.6f;
  static constexpr float kMinSigmaNodes = 0.7f;
  static constexpr float kMaxSigmaNodes = 16.0f / 3.0f;
  MarchingCubes(gpu::Context& context, const sim::Box& tank, int resolution, float particle_radius);

  // The resolution McStyle's 0 means: a node per particle spacing along the longest side, 16 to
  // 256. Throws std::invalid_argument for a radius that is not positive.
  static int resolution_for(const sim::Box& tank, float particle_radius);

  bool fits(const sim::Box& tank, int resolution, float particle_radius) const;
  // The field (splat and blur), then the triangles from it; afterwards vertices() and
  // draw_buffer() are ready for the vertex shader and vkCmdDrawIndirect.
  // The first also fills the tables and zeroes the splat.
  void record_field(VkCommandBuffer commands, const ParticleView& particles, float threshold);
  void record_triangles(VkCommandBuffer commands, const ParticleView& particles,
                        float threshold) const;
  VkDeviceAddress vertices() const { return vertices_.address(); }
  VkBuffer draw_buffer() const { return draw_.get(); }
  glm::ivec3 nodes() const { return nodes_; }

 private:
  McConstants constants_for(const ParticleView& particles, float threshold) const;

  sim::Box tank_;
  int resolution_;
  float particle_radius_;
  float spacing_, sigma_nodes_;
  int reach_;  // the blur's taps on each side
  glm::vec3 origin_;
  glm::ivec3 nodes_;
  float inverse_rest_;
  std::uint32_t max_vertices_;
  gpu::ComputePipeline splat_pass_, blur_pass_, triangles_pass_, clamp_pass_;
  gpu::Buffer tables_, splat_, field_, scratch_, vertices_, draw_;
  gpu::Buffer tables_upload_;  // the tables as the host wrote them, copied by the first frame
  bool initialised_ = false;   // the first frame's commands are recorded
};

}  // namespace fluidcast::render

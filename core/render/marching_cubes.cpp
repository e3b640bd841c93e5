#include "marching_cubes.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "fluidcast/gpu/transfer.h"
#include "fluidcast_shaders/fluidcast_render.h"
#include "marching_cubes_tables.h"

namespace fluidcast::render {
namespace {

constexpr std::uint32_t kGroup = 64;
constexpr std::uint32_t kVertexCap = 3u << 20;  // 96 MiB of vertices at most; whole triangles

// The field's value inside a cubic lattice at rest (spacing d = 2 radii), with the kernel
// (1 − r²/R²)³, summed around a lattice point: the normalisation that makes the field 1 there.
float rest_sum(float spacing, float radius) {
  const int reach = static_cast<int>(std::ceil(radius / spacing));
  double sum = 0.0;
  for (int k = -reach; k <= reach; ++k)
    for (int j = -reach; j <= reach; ++j)
      for (int i = -reach; i <= reach; ++i) {
        const double q =
            1.0 - (i * i + j * j + k * k) * double(spacing) * spacing / (double(radius) * radius);
        if (q > 0.0) sum += q * q * q;
      }
  return static_cast<float>(sum);
}

std::vector<std::int32_t> packed_tables() {
  const auto& tables = MarchingCubesTables::get();
  std::vector<std::int32_t> packed(256 * 16 + 256, -1);
  for (int pattern = 0; pattern < 256; ++pattern) {
    for (int k = 0; k < 3 * MarchingCubesTables::kMaxTriangles + 1; ++k) {
      packed[pattern * 16 + k] = tables.triangles[pattern][k];
    }
    packed[256 * 16 + pattern] = tables.triangle_count[pattern];
  }
  return packed;
}

}  // namespace

MarchingCubes::MarchingCubes(gpu::Context& context, const sim::Box& tank, int resolution,
                             float particle_radius)
    : tank_(tank),
      resolution_(resolution),
      particle_radius_(particle_radius),
      field_pass_(context, shaders::render_mc_field_comp, sizeof(McConstants), kGroup),
      triangles_pass_(context, shaders::render_mc_triangles_comp, sizeof(McConstants), kGroup),
      clamp_pass_(context, shaders::render_mc_clamp_comp, sizeof(McConstants), kGroup) {
  if (resolution < 4 || resolution > 512) {
    throw std::invalid_argument("marching cubes: resolution " + std::to_string(resolution) +
                                " is outside 4 to 512 nodes");
  }
  const glm::vec3 size = tank.size();
  spacing_ = std::max({size.x, size.y, size.z}) / static_cast<float>(resolution - 1);
  const float particle_spacing = 2.0f * particle_radius;
  field_radius_ = std::max(2.0f * particle_spacing, 1.01f * spacing_);
  // Enough nodes outside the tank that the field falls to zero there and the surface closes.
  const int margin = static_cast<int>(std::ceil(field_radius_ / spacing_)) + 1;
  origin_ = tank.min - glm::vec3(static_cast<float>(margin) * spacing_);
  nodes_ = glm::ivec3(glm::ceil(size / spacing_)) + 2 * margin + 1;
  inverse_rest_sum_ = 1.0f / rest_sum(particle_spacing, field_radius_);
  const std::uint64_t cells = std::uint64_t(nodes_.x - 1) * (nodes_.y - 1) * (nodes_.z - 1);
  max_vertices_ = static_cast<std::uint32_t>(std::min<std::uint64_t>(cells * 15, kVertexCap));

  const auto tables = packed_tables();
  tables_ = gpu::Buffer(context, tables.size() * sizeof(std::int32_t), gpu::MemoryDomain::device);
  gpu::upload<std::int32_t>(context, tables_, tables);
  field_ = gpu::Buffer(context, std::uint64_t(nodes_.x) * nodes_.y * nodes_.z * 4,
                       gpu::MemoryDomain::device);
  vertices_ = gpu::Buffer(context, std::uint64_t(max_vertices_) * 32, gpu::MemoryDomain::device);
  draw_ = gpu::Buffer(context, sizeof(VkDrawIndirectCommand), gpu::MemoryDomain::device);
}

bool MarchingCubes::fits(const sim::Box& tank, int resolution, float particle_radius) const {
  return tank.min == tank_.min && tank.max == tank_.max && resolution == resolution_ &&
         particle_radius == particle_radius_;
}

void MarchingCubes::record(VkCommandBuffer commands, const ParticleView& particles,
                           float threshold, gpu::TimestampQueries& timestamps) const {
  const McConstants constants{particles.position,
                              field_.address(),
                              tables_.address(),
                              vertices_.address(),
                              draw_.address(),
                              glm::vec4(origin_, spacing_),
                              glm::ivec4(nodes_, static_cast<int>(particles.count)),
                              field_radius_,
                              inverse_rest_sum_,
                              threshold,
                              max_vertices_};
  vkCmdFillBuffer(commands, field_.get(), 0, VK_WHOLE_SIZE, 0);
  const VkDrawIndirectCommand empty{0, 1, 0, 0};
  vkCmdUpdateBuffer(commands, draw_.get(), 0, sizeof(empty), &empty);
  gpu::transfer_to_compute_barrier(commands);
  field_pass_.dispatch(commands, constants, particles.count);
  gpu::compute_barrier(commands);
  timestamps.mark(commands);
  const std::uint64_t cells = std::uint64_t(nodes_.x - 1) * (nodes_.y - 1) * (nodes_.z - 1);
  triangles_pass_.dispatch(commands, constants, cells);
  gpu::compute_barrier(commands);
  clamp_pass_.dispatch(commands, constants, 1);
  timestamps.mark(commands);
  gpu::memory_barrier(commands, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                      VK_PIPELINE_STAGE_DRAW_INDIRECT_BIT | VK_PIPELINE_STAGE_VERTEX_SHADER_BIT,
                      VK_ACCESS_INDIRECT_COMMAND_READ_BIT | VK_ACCESS_SHADER_READ_BIT);
}

}  // namespace fluidcast::render

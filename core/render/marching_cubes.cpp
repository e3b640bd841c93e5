#include "marching_cubes.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "fluidcast_shaders/fluidcast_render.h"
#include "marching_cubes_tables.h"

namespace fluidcast::render {
namespace {

constexpr std::uint32_t kGroup = 64;
constexpr std::uint32_t kVertexCap = 3u << 20;  // 96 MiB of vertices at most; whole triangles

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

int checked_resolution(int resolution) {
  if (resolution < 4 || resolution > 512) {
    throw std::invalid_argument("marching cubes: resolution " + std::to_string(resolution) +
                                " is outside 4 to 512 nodes (0: from the particle size)");
  }
  return resolution;
}

// The blur's specialisation constants: the taps a side, then the weights of taps 0 to 16 (a
// Gaussian of σ nodes, normalised over −reach…reach; 0 beyond).
std::array<std::uint32_t, 18> blur_constants(float sigma, int reach) {
  std::array<float, 17> weights{};
  float sum = 0.0f;
  for (int k = 0; k <= reach; ++k) {
    weights[k] = std::exp(-0.5f * float(k * k) / (sigma * sigma));
    sum += k == 0 ? weights[k] : 2.0f * weights[k];
  }
  std::array<std::uint32_t, 18> constants{static_cast<std::uint32_t>(reach)};
  for (int k = 0; k <= 16; ++k) constants[k + 1] = std::bit_cast<std::uint32_t>(weights[k] / sum);
  return constants;
}

float longest_side(const sim::Box& tank) {
  const glm::vec3 size = tank.size();
  return std::max({size.x, size.y, size.z});
}

}  // namespace

MarchingCubes::MarchingCubes(gpu::Context& context, const sim::Box& tank, int resolution,
                             float particle_radius)
    : tank_(tank),
      resolution_(checked_resolution(resolution)),
      particle_radius_(particle_radius),
      spacing_(longest_side(tank) / static_cast<float>(resolution - 1)),
      sigma_nodes_(
          std::clamp(kSigmaRadii * particle_radius / spacing_, kMinSigmaNodes, kMaxSigmaNodes)),
      reach_(static_cast<int>(std::ceil(3.0f * sigma_nodes_ - 1e-4f))),
      splat_pass_(context, shaders::render_mc_splat_comp, sizeof(McConstants), kGroup),
      blur_pass_(context, shaders::render_mc_blur_comp, sizeof(McConstants), kGroup,
                 blur_constants(sigma_nodes_, reach_)),
      triangles_pass_(context, shaders::render_mc_triangles_comp, sizeof(McConstants), kGroup),
      clamp_pass_(context, shaders::render_mc_clamp_comp, sizeof(McConstants), kGroup) {
  // Enough nodes outside the tank that the field falls to zero there and the surface closes.
  const int margin = reach_ + 2;
  origin_ = tank.min - glm::vec3(static_cast<float>(margin) * spacing_);
  nodes_ = glm::ivec3(glm::ceil(tank.size() / spacing_)) + 2 * margin + 1;
  // At rest a node's cell of the grid holds (spacing / particle spacing)³ particles, each
  // splatting a unit weight; the blur keeps the mean.
  inverse_rest_ = std::pow(2.0f * particle_radius / spacing_, 3.0f);
  const std::uint64_t cells = std::uint64_t(nodes_.x - 1) * (nodes_.y - 1) * (nodes_.z - 1);
  max_vertices_ = static_cast<std::uint32_t>(std::min<std::uint64_t>(cells * 15, kVertexCap));

  const auto tables = packed_tables();
  const std::uint64_t table_bytes = tables.size() * sizeof(std::int32_t);
  tables_ = gpu::Buffer(context, table_bytes, gpu::MemoryDomain::device);
  tables_upload_ = gpu::Buffer(context, table_bytes, gpu::MemoryDomain::upload);
  std::copy(tables.begin(), tables.end(), tables_upload_.mapped<std::int32_t>().begin());
  const std::uint64_t node_bytes = std::uint64_t(nodes_.x) * nodes_.y * nodes_.z * 4;
  for (gpu::Buffer* buffer : {&splat_, &field_, &scratch_}) {
    *buffer = gpu::Buffer(context, node_bytes, gpu::MemoryDomain::device);
  }
  vertices_ = gpu::Buffer(context, std::uint64_t(max_vertices_) * 32, gpu::MemoryDomain::device);
  draw_ = gpu::Buffer(context, sizeof(VkDrawIndirectCommand), gpu::MemoryDomain::device);
}

int MarchingCubes::resolution_for(const sim::Box& tank, float particle_radius) {
  if (!(particle_radius > 0.0f && std::isfinite(particle_radius))) {
    throw std::invalid_argument("marching cubes: the particle radius must be positive");
  }
  const float nodes = std::ceil(longest_side(tank) / (2.0f * particle_radius)) + 1.0f;
  return static_cast<int>(std::clamp(nodes, 16.0f, 256.0f));
}

bool MarchingCubes::fits(const sim::Box& tank, int resolution, float particle_radius) const {
  return tank.min == tank_.min && tank.max == tank_.max && resolution == resolution_ &&
         particle_radius == particle_radius_;
}

McConstants MarchingCubes::constants_for(const ParticleView& particles, float threshold) const {
  return McConstants{particles.position,
                     splat_.address(),
                     0,
                     0,
                     field_.address(),
                     tables_.address(),
                     vertices_.address(),
                     draw_.address(),
                     glm::vec4(origin_, spacing_),
                     glm::ivec4(nodes_, static_cast<int>(particles.count)),
                     0,
                     inverse_rest_,
                     threshold,
                     max_vertices_};
}

void MarchingCubes::record_field(VkCommandBuffer commands, const ParticleView& particles,
                                 float threshold) {
  McConstants constants = constants_for(particles, threshold);
  if (!initialised_) {
    // In the first frame's commands rather than a submission of their own, which would wait for
    // everything queued before it. The splat is zeroed once; afterwards the blur's y pass clears
    // it behind itself.
    const VkBufferCopy all{0, 0, tables_.size()};
    vkCmdCopyBuffer(commands, tables_upload_.get(), tables_.get(), 1, &all);
    vkCmdFillBuffer(commands, splat_.get(), 0, VK_WHOLE_SIZE, 0);
    initialised_ = true;
  }
  const VkDrawIndirectCommand empty{0, 1, 0, 0};
  vkCmdUpdateBuffer(commands, draw_.get(), 0, sizeof(empty), &empty);
  gpu::transfer_to_compute_barrier(commands);
  splat_pass_.dispatch(commands, constants, particles.count);
  gpu::compute_barrier(commands);
  // x: splat → field, y: field → scratch, z: scratch → field.
  const std::uint64_t nodes = std::uint64_t(nodes_.x) * nodes_.y * nodes_.z;
  const VkDeviceAddress outputs[3] = {field_.address(), scratch_.address(), field_.address()};
  for (int axis = 0; axis < 3; ++axis) {
    constants.axis = axis;
    constants.blur_in = axis == 0 ? 0 : outputs[axis - 1];
    constants.blur_out = outputs[axis];
    blur_pass_.dispatch(commands, constants, nodes);
    gpu::compute_barrier(commands);
  }
}

void MarchingCubes::record_triangles(VkCommandBuffer commands, const ParticleView& particles,
                                     float threshold) const {
  const McConstants constants = constants_for(particles, threshold);
  const std::uint64_t cells = std::uint64_t(nodes_.x - 1) * (nodes_.y - 1) * (nodes_.z - 1);
  triangles_pass_.dispatch(commands, constants, cells);
  gpu::compute_barrier(commands);
  clamp_pass_.dispatch(commands, constants, 1);
  gpu::memory_barrier(commands, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                      VK_PIPELINE_STAGE_DRAW_INDIRECT_BIT | VK_PIPELINE_STAGE_VERTEX_SHADER_BIT,
                      VK_ACCESS_INDIRECT_COMMAND_READ_BIT | VK_ACCESS_SHADER_READ_BIT);
}

}  // namespace fluidcast::render

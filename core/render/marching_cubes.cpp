#include "marching_cubes.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <numeric>
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

// The case tables, then the blur's weights: a Gaussian of `sigma` node spacings over ±reach,
// normalised.
std::vector<std::int32_t> packed_tables(float sigma, int reach) {
  const auto& tables = MarchingCubesTables::get();
  std::vector<std::int32_t> packed(256 * 16 + 256, -1);
  for (int pattern = 0; pattern < 256; ++pattern) {
    for (int k = 0; k < 3 * MarchingCubesTables::kMaxTriangles + 1; ++k) {
      packed[pattern * 16 + k] = tables.triangles[pattern][k];
    }
    packed[256 * 16 + pattern] = tables.triangle_count[pattern];
  }
  std::vector<float> weights;
  for (int k = -reach; k <= reach; ++k) weights.push_back(std::exp(-0.5f * k * k / (sigma * sigma)));
  const float sum = std::accumulate(weights.begin(), weights.end(), 0.0f);
  for (float weight : weights) packed.push_back(std::bit_cast<std::int32_t>(weight / sum));
  return packed;
}

}  // namespace

MarchingCubes::MarchingCubes(gpu::Context& context, const sim::Box& tank, int resolution,
                             float particle_radius)
    : tank_(tank),
      resolution_(resolution),
      particle_radius_(particle_radius),
      splat_pass_(context, shaders::render_mc_splat_comp, sizeof(McConstants), kGroup),
      blur_pass_(context, shaders::render_mc_blur_comp, sizeof(McConstants), kGroup),
      triangles_pass_(context, shaders::render_mc_triangles_comp, sizeof(McConstants), kGroup),
      clamp_pass_(context, shaders::render_mc_clamp_comp, sizeof(McConstants), kGroup) {
  if (resolution < 4 || resolution > 512) {
    throw std::invalid_argument("marching cubes: resolution " + std::to_string(resolution) +
                                " is outside 4 to 512 nodes (0: from the particle size)");
  }
  const glm::vec3 size = tank.size();
  spacing_ = std::max({size.x, size.y, size.z}) / static_cast<float>(resolution - 1);
  const float sigma_nodes = std::max(kSigmaRadii * particle_radius / spacing_, kMinSigmaNodes);
  reach_ = static_cast<int>(std::ceil(3.0f * sigma_nodes));
  // Enough nodes outside the tank that the field falls to zero there and the surface closes.
  const int margin = reach_ + 2;
  origin_ = tank.min - glm::vec3(static_cast<float>(margin) * spacing_);
  nodes_ = glm::ivec3(glm::ceil(size / spacing_)) + 2 * margin + 1;
  // At rest a node's cell of the grid holds (spacing / particle spacing)³ particles, each
  // splatting a unit weight; the blur keeps the mean.
  inverse_rest_ = std::pow(2.0f * particle_radius / spacing_, 3.0f);
  const std::uint64_t cells = std::uint64_t(nodes_.x - 1) * (nodes_.y - 1) * (nodes_.z - 1);
  max_vertices_ = static_cast<std::uint32_t>(std::min<std::uint64_t>(cells * 15, kVertexCap));

  const auto tables = packed_tables(sigma_nodes, reach_);
  tables_ = gpu::Buffer(context, tables.size() * sizeof(std::int32_t), gpu::MemoryDomain::device);
  gpu::upload<std::int32_t>(context, tables_, tables);
  const std::uint64_t node_bytes = std::uint64_t(nodes_.x) * nodes_.y * nodes_.z * 4;
  for (gpu::Buffer* buffer : {&splat_, &field_, &scratch_}) {
    *buffer = gpu::Buffer(context, node_bytes, gpu::MemoryDomain::device);
  }
  // Zero before the first frame; afterwards the blur's y pass clears it behind itself.
  context.run_now(
      [this](VkCommandBuffer commands) { vkCmdFillBuffer(commands, splat_.get(), 0, VK_WHOLE_SIZE, 0); });
  vertices_ = gpu::Buffer(context, std::uint64_t(max_vertices_) * 32, gpu::MemoryDomain::device);
  draw_ = gpu::Buffer(context, sizeof(VkDrawIndirectCommand), gpu::MemoryDomain::device);
}

bool MarchingCubes::fits(const sim::Box& tank, int resolution, float particle_radius) const {
  return tank.min == tank_.min && tank.max == tank_.max && resolution == resolution_ &&
         particle_radius == particle_radius_;
}

void MarchingCubes::record(VkCommandBuffer commands, const ParticleView& particles,
                           float threshold, gpu::TimestampQueries& timestamps) const {
  McConstants constants{particles.position,
                        splat_.address(),
                        0,
                        0,
                        field_.address(),
                        tables_.address(),
                        vertices_.address(),
                        draw_.address(),
                        glm::vec4(origin_, spacing_),
                        glm::ivec4(nodes_, static_cast<int>(particles.count)),
                        reach_,
                        0,
                        inverse_rest_,
                        threshold,
                        max_vertices_};
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

#include "anisotropy.h"

#include <utility>

#include "fluidcast/gpu/transfer.h"
#include "fluidcast_shaders/fluidcast_render.h"
#include "frame_params.h"

namespace fluidcast::render {
namespace {

constexpr std::uint32_t kGroupSize = 128;
constexpr std::uint64_t kShapeBytes = 2 * sizeof(glm::vec4);

void compute_to_compute(VkCommandBuffer commands) {
  gpu::memory_barrier(commands, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                      VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                      VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
}

}  // namespace

Anisotropy::Anisotropy(gpu::Context& context)
    : context_(&context),
      gather_(context, shaders::render_anisotropy_gather_comp, sizeof(AnisotropyConstants),
              kGroupSize),
      pass_(context, shaders::render_anisotropy_comp, sizeof(AnisotropyConstants), kGroupSize) {}

void Anisotropy::record(VkCommandBuffer commands, const ParticleView& particles,
                        const sim::Box& tank, const SsfrStyle& style) {
  const GridFor wanted{tank.min, tank.max, kSearchRadii * particles.radius};
  if (grid_for_ != wanted) {
    auto grid = std::make_unique<sim::gpu_solver::GpuNeighbourGrid>(
        *context_, sim::GridGeometry(tank, wanted.search_radius), particles.count);
    if (grid_) context_->retire(std::move(grid_));  // frames in flight may still read it
    grid_ = std::move(grid);
    grid_for_ = wanted;
  }
  grid_->reserve(particles.count);
  if (particles.count > capacity_) {
    gpu::Buffer sorted(*context_, particles.count * sizeof(glm::vec4), gpu::MemoryDomain::device);
    gpu::Buffer centres(*context_, particles.count * sizeof(glm::vec4), gpu::MemoryDomain::device);
    gpu::Buffer shapes(*context_, particles.count * kShapeBytes, gpu::MemoryDomain::device);
    context_->retire(std::exchange(sorted_positions_, std::move(sorted)));
    context_->retire(std::exchange(centres_, std::move(centres)));
    context_->retire(std::exchange(shapes_, std::move(shapes)));
    capacity_ = particles.count;
  }

  grid_->record_clear(commands);
  gpu::memory_barrier(commands, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                      VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                      VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
  std::vector<sim::GpuStepBatch::Pass> build;
  grid_->append_build(build, particles.position, particles.count, 0);
  for (const sim::GpuStepBatch::Pass& pass : build) {
    pass.record(commands);
    compute_to_compute(commands);
  }

  const sim::GridGeometry& geometry = grid_->geometry();
  AnisotropyConstants constants{};
  constants.position = particles.position;
  constants.order = grid_->order().address();
  constants.cell_start = grid_->cell_start().address();
  constants.sorted_cell = grid_->sorted_cell().address();
  constants.sorted_position = sorted_positions_.address();
  constants.centre = centres_.address();
  constants.shape = shapes_.address();
  constants.origin = glm::vec4(geometry.origin, 0.0f);
  constants.dims = glm::ivec4(geometry.dims, 0);
  constants.particle_count = particles.count;
  constants.radius = particles.radius;
  constants.search_radius = wanted.search_radius;
  constants.max_stretch = style.max_stretch;
  constants.centre_smoothing = style.centre_smoothing;
  constants.spray_below = static_cast<std::uint32_t>(style.spray_neighbours);
  constants.max_candidates = kMaxCandidates;
  gather_.dispatch(commands, constants, particles.count);
  compute_to_compute(commands);
  pass_.dispatch(commands, constants, particles.count);
  gpu::memory_barrier(commands, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                      VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT);
}

}  // namespace fluidcast::render

#include "fluidcast/sim/gpu_neighbour_grid.h"

#include <cstddef>
#include <glm/glm.hpp>
#include <utility>

#include "fluidcast_shaders/fluidcast_sim.h"

namespace fluidcast::sim::gpu_solver {
namespace {

// Mirrors shaders/common/grid_pass.glsl (std430 push constants).
struct GridPass {
  VkDeviceAddress key, cell_of, rank, cell_start, order, sorted_cell;
  glm::vec4 origin;  // w: 1 / cell size
  glm::ivec4 dims;
  std::uint32_t particle_count;
};
static_assert(offsetof(GridPass, sorted_cell) == 40);
static_assert(offsetof(GridPass, origin) == 48);
static_assert(offsetof(GridPass, dims) == 64);
static_assert(offsetof(GridPass, particle_count) == 80);

// Mirrors shaders/common/scan_pass.glsl.
struct ScanPass {
  VkDeviceAddress data, block_sums;
  std::uint32_t count;
  std::uint32_t write_block_sums;
};
static_assert(offsetof(ScanPass, count) == 16 && offsetof(ScanPass, write_block_sums) == 20);

std::uint32_t blocks(std::uint32_t count) {
  return (count + GpuNeighbourGrid::kScanBlock - 1) / GpuNeighbourGrid::kScanBlock;
}

GridPass grid_pass(const GpuNeighbourGrid& grid, VkDeviceAddress key, std::uint32_t count) {
  GridPass pass{};
  pass.key = key;
  pass.cell_of = grid.cell_of().address();
  pass.rank = grid.rank().address();
  pass.cell_start = grid.cell_start().address();
  pass.order = grid.order().address();
  pass.sorted_cell = grid.sorted_cell().address();
  pass.origin = glm::vec4(grid.geometry().origin, grid.geometry().inv_cell_size);
  pass.dims = glm::ivec4(grid.geometry().dims, 0);
  pass.particle_count = count;
  return pass;
}

}  // namespace

std::uint64_t GpuNeighbourGrid::bytes_for_cells(std::size_t cells) {
  // cell_start plus the block totals of every level (a geometric series below cells / (block − 1)).
  return (cells + 1 + cells / (kScanBlock - 1) + 16) * sizeof(std::uint32_t);
}

GpuNeighbourGrid::Pipelines::Pipelines(gpu::Context& c)
    : count(c, shaders::sim_grid_count_comp, sizeof(GridPass), kGroupSize),
      scan(c, shaders::sim_grid_scan_comp, sizeof(ScanPass), kScanGroupSize),
      scan_add(c, shaders::sim_grid_scan_add_comp, sizeof(ScanPass), kScanGroupSize),
      scatter(c, shaders::sim_grid_scatter_comp, sizeof(GridPass), kGroupSize) {}

std::vector<PassStatistics> GpuNeighbourGrid::pipeline_statistics(gpu::Context& context) {
  const Pipelines p(context);
  return {{"grid_count", p.count.statistics()},
          {"grid_scan", p.scan.statistics()},
          {"grid_scan_add", p.scan_add.statistics()},
          {"grid_scatter", p.scatter.statistics()}};
}

GpuNeighbourGrid::GpuNeighbourGrid(gpu::Context& context, const GridGeometry& geometry,
                                   std::size_t capacity)
    : context_(&context), geometry_(geometry), pipelines_(context) {
  const auto cells = static_cast<std::uint32_t>(geometry.cell_count());
  cell_start_ = gpu::Buffer(context, (std::uint64_t{cells} + 1) * sizeof(std::uint32_t),
                            gpu::MemoryDomain::device);
  // Level k holds level_counts_[k] elements; its block totals are level k + 1.
  level_counts_.push_back(cells + 1);
  while (level_counts_.back() > kScanBlock) {
    const std::uint32_t totals = blocks(level_counts_.back());
    block_sums_.emplace_back(context, std::uint64_t{totals} * sizeof(std::uint32_t),
                             gpu::MemoryDomain::device);
    level_counts_.push_back(totals);
  }
  reserve(capacity);
}

void GpuNeighbourGrid::reserve(std::size_t capacity) {
  if (capacity <= capacity_ && cell_of_) return;
  capacity = std::max(capacity, capacity_);
  const std::uint64_t bytes = std::uint64_t{capacity} * sizeof(std::uint32_t);
  // All four first, so that running out of memory leaves the grid as it was.
  gpu::Buffer cell_of(*context_, bytes, gpu::MemoryDomain::device);
  gpu::Buffer rank(*context_, bytes, gpu::MemoryDomain::device);
  gpu::Buffer order(*context_, bytes, gpu::MemoryDomain::device);
  gpu::Buffer sorted_cell(*context_, bytes, gpu::MemoryDomain::device);
  // Steps and frames in flight may still use the old ones.
  context_->retire(std::exchange(cell_of_, std::move(cell_of)));
  context_->retire(std::exchange(rank_, std::move(rank)));
  context_->retire(std::exchange(order_, std::move(order)));
  context_->retire(std::exchange(sorted_cell_, std::move(sorted_cell)));
  capacity_ = capacity;
}

void GpuNeighbourGrid::record_clear(VkCommandBuffer commands) const {
  vkCmdFillBuffer(commands, cell_start_.get(), 0, VK_WHOLE_SIZE, 0);
}

void GpuNeighbourGrid::append_build(std::vector<GpuStepBatch::Pass>& passes, VkDeviceAddress key,
                                    std::uint32_t count, int stage) const {
  append_count(passes, key, count, stage);
  append_scan(passes, stage);
  passes.push_back({stage, 0, [this, pass = grid_pass(*this, key, count)](VkCommandBuffer c) {
                      pipelines_.scatter.dispatch(c, pass, pass.particle_count);
                    }});
}

void GpuNeighbourGrid::append_count(std::vector<GpuStepBatch::Pass>& passes, VkDeviceAddress key,
                                    std::uint32_t count, int stage) const {
  passes.push_back({stage, 0, [this, pass = grid_pass(*this, key, count)](VkCommandBuffer c) {
                      pipelines_.count.dispatch(c, pass, pass.particle_count);
                    }});
}

void GpuNeighbourGrid::append_scan(std::vector<GpuStepBatch::Pass>& passes, int stage) const {
  const auto add = [&](std::function<void(VkCommandBuffer)> record) {
    passes.push_back({stage, 0, std::move(record)});
  };
  // Up the levels: scan each in place, writing its block totals into the next.
  const std::size_t levels = level_counts_.size();
  for (std::size_t k = 0; k < levels; ++k) {
    ScanPass scan{};
    scan.data = k == 0 ? cell_start_.address() : block_sums_[k - 1].address();
    scan.block_sums = k + 1 < levels ? block_sums_[k].address() : 0;
    scan.count = level_counts_[k];
    scan.write_block_sums = k + 1 < levels ? 1 : 0;
    add([this, scan](VkCommandBuffer c) {
      pipelines_.scan.dispatch(c, scan, std::uint64_t{blocks(scan.count)} * kScanGroupSize);
    });
  }
  // Down again: add each block's scanned total to its elements.
  for (std::size_t k = levels - 1; k-- > 0;) {
    ScanPass scan_add{};
    scan_add.data = k == 0 ? cell_start_.address() : block_sums_[k - 1].address();
    scan_add.block_sums = block_sums_[k].address();
    scan_add.count = level_counts_[k];
    add([this, scan_add](VkCommandBuffer c) {
      pipelines_.scan_add.dispatch(c, scan_add, scan_add.count);
    });
  }
}

}  // namespace fluidcast::sim::gpu_solver

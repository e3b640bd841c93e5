// The neighbour grid on the GPU, by counting sort as the talk builds it: an atomic count per cell
// that also gives each particle its rank in the cell, a work-efficient multi-level exclusive prefix
// sum over the cells, and a scatter that writes each particle's sorted slot. About five dispatches
// for the whole build (three where a solver counts and scatters in passes of its own). Cell
// geometry is the CPU grid's (GridGeometry), so both put every particle in the same cell and give
// the same cell ranges; within a cell the order follows the atomics.
#pragma once

#include <cstdint>
#include <vector>

#include "fluidcast/gpu/buffer.h"
#include "fluidcast/gpu/compute_pipeline.h"
#include "fluidcast/sim/gpu_solver_statistics.h"
#include "fluidcast/sim/gpu_step_batch.h"
#include "fluidcast/sim/neighbour_grid.h"

namespace fluidcast::sim::gpu_solver {

class GpuNeighbourGrid {
 public:
  static constexpr std::uint32_t kGroupSize = 128;
  static constexpr std::uint32_t kScanGroupSize = 256;
  // 16: a block of 4096, so that up to 16.7M cells (a 1M-particle tank's 5M) take two levels of
  // the scan, three dispatches, rather than three levels and five; each dispatch of the grid
  // build is a barrier the whole device waits at.
  static constexpr std::uint32_t kScanItemsPerInvocation = 16;  // SCAN_ITEMS_PER_INVOCATION
  static constexpr std::uint32_t kScanBlock = kScanGroupSize * kScanItemsPerInvocation;

  // GPU memory the grid needs, for the up-front check of a particle count.
  static std::uint64_t bytes_per_particle() { return 4 * sizeof(std::uint32_t); }
  static std::uint64_t bytes_for_cells(std::size_t cells);

  GpuNeighbourGrid(gpu::Context& context, const GridGeometry& geometry, std::size_t capacity);

  // What the driver says of the grid's passes (gpu_solver_pipeline_statistics).
  static std::vector<PassStatistics> pipeline_statistics(gpu::Context& context);

  // Makes room for `capacity` particles (never shrinks); unchanged if it throws.
  void reserve(std::size_t capacity);

  // The build for the first `count` positions (vec4) at `key`, as passes (tagged `stage`) that
  // start once record_clear() is done: record that in the pass before, to save a barrier.
  void record_clear(VkCommandBuffer commands) const;
  void append_build(std::vector<GpuStepBatch::Pass>& passes, VkDeviceAddress key,
                    std::uint32_t count, int stage) const;
  // The build's parts, for a solver that folds the first and the last into passes of its own
  // (grid_count and grid_scatter in shaders/common/grid.glsl, with this grid's buffers):
  // append_count is the build's first pass, append_scan the prefix sum between.
  void append_count(std::vector<GpuStepBatch::Pass>& passes, VkDeviceAddress key,
                    std::uint32_t count, int stage) const;
  void append_scan(std::vector<GpuStepBatch::Pass>& passes, int stage) const;

  const GridGeometry& geometry() const { return geometry_; }
  // Sorted slot → particle index; cell c's slots are [cell_start[c], cell_start[c + 1]).
  const gpu::Buffer& order() const { return order_; }
  const gpu::Buffer& cell_start() const { return cell_start_; }
  // Sorted slot → the cell its particle was sorted into.
  const gpu::Buffer& sorted_cell() const { return sorted_cell_; }
  // Particle → its cell, and its place in the cell: the count's results, which the scatter reads.
  const gpu::Buffer& cell_of() const { return cell_of_; }
  const gpu::Buffer& rank() const { return rank_; }

 private:
  gpu::Context* context_;
  GridGeometry geometry_;
  struct Pipelines {
    explicit Pipelines(gpu::Context& context);
    gpu::ComputePipeline count, scan, scan_add, scatter;
  };
  Pipelines pipelines_;
  std::size_t capacity_ = 0;
  gpu::Buffer cell_of_, rank_, order_, sorted_cell_;
  gpu::Buffer cell_start_;
  std::vector<std::uint32_t> level_counts_;  // elements at each level of the prefix sum
  std::vector<gpu::Buffer> block_sums_;      // block totals of level k, scanned as level k + 1
};

}  // namespace fluidcast::sim::gpu_solver

// For each particle, the indices of the others within a radius, found once per substep through
// the grid and then read by every solver pass (PBF reads them 2·iterations + 2 or 3 times a
// substep).
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <span>
#include <vector>

#include "fluidcast/sim/fork_join_pool.h"
#include "fluidcast/sim/lanes.h"
#include "fluidcast/sim/neighbour_grid.h"

namespace fluidcast::sim {

class NeighbourList {
 public:
  // `positions` must be in the grid's sorted order (after apply_order). A particle is not its
  // own neighbour. Each list is in increasing index order. At most `max_candidates` slots are
  // examined per particle and at most `max_neighbours` listed (FluidConstants, the GPU solver's
  // rule too): in a clump a list is cut short, and the work and memory stay linear in the count.
  void build(ForkJoinPool& pool, const NeighbourGrid& grid, std::span<const glm::vec3> positions,
             float radius, std::uint32_t max_candidates, std::uint32_t max_neighbours);

  std::span<const std::uint32_t> of(std::size_t i) const { return {begin_[i], count_[i]}; }
  std::size_t size() const { return count_.size(); }

  // of(i) padded to whole blocks of lanes::kWidth, for loops that take a block of neighbours at a
  // time: the entries past count hold i itself (a valid index; a loop masks them off).
  std::span<const std::uint32_t> blocks_of(std::size_t i) const {
    return {begin_[i], (count_[i] + lanes::kWidth - 1) / lanes::kWidth * lanes::kWidth};
  }

  // Every padded entry has an index in [0, pair_count()): blocks_of(i)[k] is pair first_pair(i)
  // + k, and first_pair(i) is a multiple of lanes::kWidth. Solvers keep per-pair values (kernel
  // gradients) in arrays of this size.
  std::size_t pair_count() const { return pair_count_; }
  std::size_t first_pair(std::size_t i) const { return first_pair_[i]; }

 private:
  // Sizes the lists for `positions` and copies their coordinates into xs_, ys_, zs_.
  void prepare(ForkJoinPool& pool, std::span<const glm::vec3> positions);

  // One buffer per chunk of the pool, so threads never share a growing vector.
  std::vector<std::vector<std::uint32_t>> chunk_indices_;
  std::vector<float> xs_, ys_, zs_;
  std::vector<const std::uint32_t*> begin_;
  std::vector<std::uint32_t> count_;
  std::vector<std::size_t> offset_;  // into the chunk's buffer, while building
  std::vector<std::size_t> chunk_used_;
  std::vector<std::size_t> first_pair_;
  std::size_t pair_count_ = 0;
};

}  // namespace fluidcast::sim

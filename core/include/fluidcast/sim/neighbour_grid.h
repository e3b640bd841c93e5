// Uniform grid over the tank, built by counting sort: per-cell count, exclusive prefix sum,
// scatter. The sort is stable, so the order it produces depends only on the positions.
// After build(), particles are meant to be reordered by order() (see apply_order), which makes
// each cell's particles — and a row of cells along x — contiguous in memory.
// Cells are half the search radius: the 5×5×5 cells around a particle hold 15.6 r³ of candidates
// where 3×3×3 cells of side r hold 27 r³, and the 25 rows of 5 cells stay contiguous.
#pragma once

#include <cmath>
#include <cstdint>
#include <glm/glm.hpp>
#include <span>
#include <vector>

#include "fluidcast/sim/fork_join_pool.h"
#include "fluidcast/sim/particles.h"

namespace fluidcast::sim {

// Where the cells are: shared by the CPU grid and the GPU one, which must sort identically.
struct GridGeometry {
  static constexpr int kCellsPerRadius = 2;
  static constexpr std::size_t kMaxCells = std::size_t{1} << 26;

  // Throws std::invalid_argument for a search radius that is not positive and finite, or a grid
  // of more than kMaxCells cells.
  GridGeometry(const Box& domain, float search_radius);

  // The cell of p. Positions outside the domain count in the nearest border cell; NaN in cell 0.
  // Inline: every particle asks twice a substep.
  glm::ivec3 cell_coords(glm::vec3 p) const {
    const glm::vec3 f = glm::floor((p - origin) * inv_cell_size);
    // Clamp in float first: a far-away (or non-finite) position must not overflow the int cast.
    const glm::vec3 clamped = glm::clamp(f, glm::vec3(0.0f), glm::vec3(dims - 1));
    return glm::ivec3(std::isnan(clamped.x) ? 0.0f : clamped.x,
                      std::isnan(clamped.y) ? 0.0f : clamped.y,
                      std::isnan(clamped.z) ? 0.0f : clamped.z);
  }
  std::uint32_t cell_index(glm::ivec3 c) const {
    return static_cast<std::uint32_t>(c.x + dims.x * (c.y + dims.y * c.z));
  }
  std::size_t cell_count() const {
    return static_cast<std::size_t>(dims.x) * static_cast<std::size_t>(dims.y) *
           static_cast<std::size_t>(dims.z);
  }

  glm::vec3 origin;
  float inv_cell_size;
  glm::ivec3 dims;
};

class NeighbourGrid {
 public:
  // Throws as GridGeometry does.
  NeighbourGrid(const Box& domain, float search_radius);

  static constexpr int kCellsPerRadius = GridGeometry::kCellsPerRadius;
  static constexpr std::size_t kMaxCells = GridGeometry::kMaxCells;

  // Sorts particles by cell: each particle's cell is found on the pool's threads, the counting
  // and the scatter run on the caller's. Positions outside the domain count in the nearest border
  // cell.
  void build(ForkJoinPool& pool, std::span<const glm::vec3> positions);

  // order()[k] = index, in the positions given to build(), of the particle at sorted slot k.
  std::span<const std::uint32_t> order() const { return order_; }
  // Sorted slots of cell c are [cell_start()[c], cell_start()[c + 1]).
  std::span<const std::uint32_t> cell_start() const { return cell_start_; }

  const GridGeometry& geometry() const { return geometry_; }
  glm::ivec3 dims() const { return geometry_.dims; }
  std::size_t cell_count() const { return cell_start_.size() - 1; }
  glm::ivec3 cell_coords(glm::vec3 p) const { return geometry_.cell_coords(p); }
  std::uint32_t cell_index(glm::ivec3 c) const { return geometry_.cell_index(c); }

  // Calls visit(begin, end) for the sorted-slot ranges of the cells within the search radius of
  // p's cell: one contiguous range for each row of cells along x, in increasing slot order.
  template <class Visit>
  void for_each_candidate_range(glm::vec3 p, Visit&& visit) const {
    constexpr int reach = kCellsPerRadius;
    const glm::ivec3 c = cell_coords(p);
    const glm::ivec3 dims = geometry_.dims;
    const int x0 = c.x - reach > 0 ? c.x - reach : 0;
    const int x1 = c.x + reach < dims.x ? c.x + reach : dims.x - 1;
    for (int z = c.z - reach; z <= c.z + reach; ++z) {
      if (z < 0 || z >= dims.z) continue;
      for (int y = c.y - reach; y <= c.y + reach; ++y) {
        if (y < 0 || y >= dims.y) continue;
        visit(cell_start_[cell_index({x0, y, z})], cell_start_[cell_index({x1, y, z}) + 1]);
      }
    }
  }

 private:
  GridGeometry geometry_;
  std::vector<std::uint32_t> cell_of_particle_;
  std::vector<std::uint32_t> cell_start_;  // cell_count() + 1 entries
  std::vector<std::uint32_t> cursor_;
  std::vector<std::uint32_t> order_;
};

// data[k] = old[order[k]] for every k: the one way every per-particle array is reordered.
template <class T>
void apply_order(ForkJoinPool& pool, std::span<const std::uint32_t> order, std::vector<T>& data,
                 std::vector<T>& scratch) {
  scratch.resize(data.size());
  pool.for_each(order.size(), [&](std::size_t k) { scratch[k] = data[order[k]]; });
  data.swap(scratch);
}

}  // namespace fluidcast::sim

#include "fluidcast/sim/neighbour_grid.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace fluidcast::sim {

GridGeometry::GridGeometry(const Box& domain, float search_radius) : origin(domain.min) {
  if (!std::isfinite(search_radius) || search_radius <= 0.0f) {
    throw std::invalid_argument("neighbour grid: search radius must be positive and finite, got " +
                                std::to_string(search_radius));
  }
  inv_cell_size = 1.0f / (search_radius / kCellsPerRadius);
  const glm::vec3 cells = glm::max(glm::ceil(domain.size() * inv_cell_size), glm::vec3(1.0f));
  const double total = static_cast<double>(cells.x) * cells.y * cells.z;
  if (!(total <= static_cast<double>(kMaxCells))) {
    throw std::invalid_argument("neighbour grid: " + std::to_string(total) +
                                " cells exceed the limit of " + std::to_string(kMaxCells) +
                                "; use fewer particles or a smaller tank");
  }
  dims = glm::ivec3(cells);
}

NeighbourGrid::NeighbourGrid(const Box& domain, float search_radius)
    : geometry_(domain, search_radius), cell_start_(geometry_.cell_count() + 1, 0) {}

void NeighbourGrid::build(ForkJoinPool& pool, std::span<const glm::vec3> positions) {
  const std::size_t n = positions.size();
  cell_of_particle_.resize(n);
  pool.for_each(
      n, [&](std::size_t i) { cell_of_particle_[i] = cell_index(cell_coords(positions[i])); });
  std::fill(cell_start_.begin(), cell_start_.end(), 0u);

  // Count: cell_start_[c + 1] holds the count of cell c.
  for (std::size_t i = 0; i < n; ++i) ++cell_start_[cell_of_particle_[i] + 1];
  // Exclusive prefix sum over cells.
  for (std::size_t c = 1; c < cell_start_.size(); ++c) cell_start_[c] += cell_start_[c - 1];
  // Scatter, in particle order within each cell (stable).
  cursor_.assign(cell_start_.begin(), cell_start_.end() - 1);
  order_.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    order_[cursor_[cell_of_particle_[i]]++] = static_cast<std::uint32_t>(i);
  }
}

}  // namespace fluidcast::sim

#include "fluidcast/sim/neighbour_list.h"

namespace fluidcast::sim {

void NeighbourList::build(ForkJoinPool& pool, const NeighbourGrid& grid,
                          std::span<const glm::vec3> positions, float radius) {
  const std::size_t n = positions.size();
  const float r2 = radius * radius;
  begin_.resize(n);
  count_.resize(n);
  offset_.resize(n);
  chunk_indices_.resize(pool.size());
  pool.for_chunks(n, [&](unsigned chunk, std::size_t first, std::size_t last) {
    std::vector<std::uint32_t>& out = chunk_indices_[chunk];
    out.clear();
    // Offsets first: `out` may reallocate while it grows.
    for (std::size_t i = first; i < last; ++i) {
      const glm::vec3 p = positions[i];
      offset_[i] = out.size();
      grid.for_each_candidate_range(p, [&](std::uint32_t begin, std::uint32_t end) {
        for (std::uint32_t j = begin; j < end; ++j) {
          const glm::vec3 d = p - positions[j];
          if (d.x * d.x + d.y * d.y + d.z * d.z < r2 && j != i) out.push_back(j);
        }
      });
      count_[i] = static_cast<std::uint32_t>(out.size() - offset_[i]);
    }
    for (std::size_t i = first; i < last; ++i) begin_[i] = out.data() + offset_[i];
  });
}

}  // namespace fluidcast::sim

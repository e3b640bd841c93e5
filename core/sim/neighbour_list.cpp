#include "fluidcast/sim/neighbour_list.h"

#include <algorithm>
#include <utility>

namespace fluidcast::sim {

void NeighbourList::prepare(ForkJoinPool& pool, std::span<const glm::vec3> positions) {
  const std::size_t n = positions.size();
  begin_.resize(n);
  count_.resize(n);
  offset_.resize(n);
  first_pair_.resize(n);
  chunk_indices_.resize(pool.size());
  chunk_hits_.resize(pool.size());
  chunk_used_.assign(pool.size(), 0);
  // Coordinates as separate arrays, so the distance test over a row of cells vectorises.
  xs_.resize(n);
  ys_.resize(n);
  zs_.resize(n);
  pool.for_each(n, [&](std::size_t i) {
    xs_[i] = positions[i].x;
    ys_[i] = positions[i].y;
    zs_[i] = positions[i].z;
  });
}

void NeighbourList::build(ForkJoinPool& pool, const NeighbourGrid& grid,
                          std::span<const glm::vec3> positions, float radius,
                          std::uint32_t max_candidates, std::uint32_t max_neighbours) {
  const std::size_t n = positions.size();
  const float r2 = radius * radius;
  prepare(pool, positions);
  pool.for_chunks(n, [&](unsigned chunk, std::size_t first, std::size_t last) {
    std::vector<std::uint32_t>& out = chunk_indices_[chunk];
    std::vector<std::uint32_t>& hits = chunk_hits_[chunk];
    // Offsets first: `out` may reallocate while it grows.
    std::size_t used = 0;
    for (std::size_t i = first; i < last; ++i) {
      const glm::vec3 p = positions[i];
      offset_[i] = used;
      std::uint32_t examined = 0;
      grid.for_each_candidate_range(p, [&](std::uint32_t begin, std::uint32_t end) {
        if (examined >= max_candidates || used - offset_[i] >= max_neighbours) return;
        end = begin + std::min(end - begin, max_candidates - examined);
        examined += end - begin;
        // Room for every candidate, so the loop below can write without a branch.
        if (out.size() < used + (end - begin)) out.resize(2 * (used + (end - begin)));
        const std::uint32_t length = end - begin;
        if (hits.size() < length) hits.resize(2 * length);
        const float* x = xs_.data() + begin;
        const float* y = ys_.data() + begin;
        const float* z = zs_.data() + begin;
        std::uint32_t* hit = hits.data();
        for (std::uint32_t k = 0; k < length; ++k) {
          const float dx = p.x - x[k], dy = p.y - y[k], dz = p.z - z[k];
          hit[k] = dx * dx + dy * dy + dz * dz < r2;
        }
        std::uint32_t* slot = out.data() + used;
        std::size_t found = 0;
        for (std::uint32_t k = 0; k < length; ++k) {
          slot[found] = begin + k;
          found += hit[k] & (begin + k != i);
        }
        used += std::min<std::size_t>(found, max_neighbours - (used - offset_[i]));
      });
      count_[i] = static_cast<std::uint32_t>(used - offset_[i]);
    }
    chunk_used_[chunk] = used;
    for (std::size_t i = first; i < last; ++i) begin_[i] = out.data() + offset_[i];
  });
  // The same n splits into the same chunks, so chunk bases can be added in a second pass.
  std::vector<std::size_t>& base = chunk_used_;
  std::size_t total = 0;
  for (std::size_t& used : base) total += std::exchange(used, total);
  pair_count_ = total;
  pool.for_chunks(n, [&](unsigned chunk, std::size_t first, std::size_t last) {
    for (std::size_t i = first; i < last; ++i) first_pair_[i] = base[chunk] + offset_[i];
  });
}

}  // namespace fluidcast::sim

#include "fluidcast/sim/neighbour_list.h"

#include <algorithm>
#include <array>
#include <cstring>
#include <utility>

namespace fluidcast::sim {

namespace {

using lanes::Floats;
using lanes::Ints;
using lanes::kWidth;

// For each kWidth-bit mask, its lanes packed to the front and how many there are:
// kPacked[0b0110] = {{1, 2, …}, 2}. A table, not std::popcount: without -mpopcnt that is a call.
struct PackedLanes {
  std::array<std::int32_t, kWidth> front;
  std::uint32_t count;
};
constexpr auto kPacked = [] {
  std::array<PackedLanes, 1u << kWidth> packed{};
  for (unsigned mask = 0; mask < (1u << kWidth); ++mask)
    for (std::int32_t lane = 0; lane < static_cast<std::int32_t>(kWidth); ++lane)
      if (mask & (1u << lane)) packed[mask].front[packed[mask].count++] = lane;
  return packed;
}();

// The indices first + lane of the mask's lanes, written to to[0..popcount): kWidth slots are
// written whatever the mask, so `to` needs room for kWidth.
void store_packed(std::uint32_t* to, std::uint32_t first, unsigned mask) {
  Ints offsets;
  std::memcpy(&offsets, kPacked[mask].front.data(), sizeof offsets);
  const Ints indices = offsets + static_cast<std::int32_t>(first);
  std::memcpy(to, &indices, sizeof indices);
}

// Bit b set when candidate first + b, of coordinates xs, ys, zs, lies within √r2 of p.
unsigned within(const float* xs, const float* ys, const float* zs, glm::vec3 p, float r2,
                std::uint32_t first) {
  const Floats dx = p.x - lanes::load(xs + first);
  const Floats dy = p.y - lanes::load(ys + first);
  const Floats dz = p.z - lanes::load(zs + first);
  return lanes::mask(dx * dx + dy * dy + dz * dz < r2);
}

}  // namespace

void NeighbourList::prepare(ForkJoinPool& pool, std::span<const glm::vec3> positions) {
  const std::size_t n = positions.size();
  begin_.resize(n);
  count_.resize(n);
  offset_.resize(n);
  first_pair_.resize(n);
  chunk_indices_.resize(pool.size());
  chunk_used_.assign(pool.size(), 0);
  // Coordinates as separate arrays, so the distance test over a row of cells vectorises.
  // A block may read up to kWidth − 1 entries past the last; its mask drops them.
  xs_.resize(n + kWidth - 1);
  ys_.resize(n + kWidth - 1);
  zs_.resize(n + kWidth - 1);
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
  // Locals, not members: the packed stores may alias anything, and members would be reloaded.
  const float *xs = xs_.data(), *ys = ys_.data(), *zs = zs_.data();
  pool.for_chunks(n, [&](unsigned chunk, std::size_t first, std::size_t last) {
    std::vector<std::uint32_t>& out = chunk_indices_[chunk];
    // Its data and size in locals, which the packed stores cannot alias; offsets first, as `out`
    // may reallocate while it grows.
    std::uint32_t* data = out.data();
    std::size_t room = out.size();
    const auto make_room = [&](std::size_t needed) {
      if (room >= needed) return;
      out.resize(2 * needed);
      data = out.data();
      room = out.size();
    };
    std::size_t used = 0;
    for (std::size_t i = first; i < last; ++i) {
      const glm::vec3 p = positions[i];
      const std::size_t start = used;
      offset_[i] = start;
      std::uint32_t examined = 0;
      grid.for_each_candidate_range(p, [&](std::uint32_t begin, std::uint32_t end) {
        if (examined >= max_candidates || used - start >= max_neighbours) return;
        end = begin + std::min(end - begin, max_candidates - examined);
        examined += end - begin;
        // Room for every candidate and one block past them: a block's kWidth slots are written
        // whole, hits or not.
        const std::uint32_t length = end - begin;
        make_room(used + length + kWidth);
        std::uint32_t* slot = data + used;
        std::size_t found = 0;
        for (std::uint32_t k = 0; k < length; k += kWidth) {
          const std::uint32_t first_index = begin + k;
          unsigned hits = within(xs, ys, zs, p, r2, first_index);
          if (length - k < kWidth) hits &= (1u << (length - k)) - 1u;
          if (i - first_index < kWidth) hits &= ~(1u << (i - first_index));
          store_packed(slot + found, first_index, hits);
          found += kPacked[hits].count;
        }
        used += std::min<std::size_t>(found, max_neighbours - (used - start));
      });
      count_[i] = static_cast<std::uint32_t>(used - start);
      make_room(used + kWidth);
      while ((used - start) % kWidth != 0) data[used++] = static_cast<std::uint32_t>(i);
    }
    chunk_used_[chunk] = used;
    for (std::size_t i = first; i < last; ++i) begin_[i] = data + offset_[i];
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

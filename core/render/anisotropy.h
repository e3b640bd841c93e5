// SSFR's anisotropic kernels (Yu & Turk 2013), computed each frame on the GPU from the particles
// as drawn: a grid over them (the solver's counting sort, GpuNeighbourGrid), then, per particle,
// the weighted covariance of its neighbours within two particle spacings, its principal axes, and
// an ellipsoid of the particle's volume stretched along them (at most SsfrStyle::max_stretch),
// around a centre drawn towards its neighbours (SsfrStyle::centre_smoothing). Particles with
// fewer than SsfrStyle::spray_neighbours neighbours are marked as spray. Like the solver's search,
// each particle examines at most kMaxCandidates candidates: a clump costs a bounded amount each.
// The grid is the renderer's own, not the solver's: that one was built at positions predicted
// before the step's last move and indexes the solver's own order; this one serves any particles
// (a CPU solver's upload too).
#pragma once

#include <memory>
#include <optional>

#include "fluidcast/gpu/buffer.h"
#include "fluidcast/gpu/compute_pipeline.h"
#include "fluidcast/render/frame_renderer.h"
#include "fluidcast/sim/fluid_constants.h"
#include "fluidcast/sim/gpu_neighbour_grid.h"
#include "fluidcast/sim/statistics.h"

namespace fluidcast::render {

class Anisotropy {
 public:
  // The neighbourhood's radius, in particle radii (two a spacing: FluidConstants::particle_radius):
  // the reach within which the spray's neighbours are counted, two spacings, about 33 neighbours
  // inside the fluid.
  static constexpr float kSearchRadii = 2.0f * sim::kSprayReachSpacings;
  // Candidates examined per particle, at most: the solver's rule (FluidConstants::max_candidates)
  // for this window — 5×5×5 cells of half the search radius, 2.5 × 2 spacings a side.
  static constexpr std::uint32_t kMaxCandidates =
      static_cast<std::uint32_t>(sim::FluidConstants::kCandidatesOverRest * 5 * 5 * 5);

  explicit Anisotropy(gpu::Context& context);

  // Records the grid's build and the ellipsoids of `particles` (count > 0) in `tank`; for the
  // compute passes recorded after it, centres() and shapes() hold them (anisotropy.comp's
  // layout). Throws std::invalid_argument when the tank needs more grid cells than a grid has.
  void record(VkCommandBuffer commands, const ParticleView& particles, const sim::Box& tank,
              const SsfrStyle& style);

  const gpu::Buffer& centres() const { return centres_; }
  const gpu::Buffer& shapes() const { return shapes_; }

 private:
  struct GridFor {
    glm::vec3 tank_min, tank_max;
    float search_radius;
    bool operator==(const GridFor&) const = default;
  };

  gpu::Context* context_;
  gpu::ComputePipeline gather_, pass_;
  std::unique_ptr<sim::gpu_solver::GpuNeighbourGrid> grid_;
  std::optional<GridFor> grid_for_;
  std::size_t capacity_ = 0;
  gpu::Buffer sorted_positions_, centres_, shapes_;
};

}  // namespace fluidcast::render

#include "fluidcast/sim/fluid_constants.h"

#include <cmath>
#include <numbers>

#include "fluidcast/sim/kernels.h"
#include "fluidcast/sim/neighbour_grid.h"

namespace fluidcast::sim {
namespace {

// The offset behind a wall at which the walls' fluid adds `share` of ρ0 to a particle half a
// spacing from it: wall_volume falls from ½ at 0 to 0 at h, so bisection finds the distance.
float wall_offset_for(const Kernels& kernels, float spacing, double share) {
  float near = 0.0f, far = kernels.radius();
  for (int halving = 0; halving < 40; ++halving) {
    const float middle = 0.5f * (near + far);
    (kernels.wall_volume(middle) > share ? near : far) = middle;
  }
  return 0.5f * (near + far) - 0.5f * spacing;
}

}  // namespace

FluidConstants derive_fluid_constants(float spacing, const SolverParams& params) {
  FluidConstants c;
  c.spacing = spacing;
  c.kernel_radius = params.kernel_ratio * spacing;
  c.rest_density = params.rest_density;
  const Kernels kernels(c.kernel_radius);
  const int reach = static_cast<int>(std::ceil(params.kernel_ratio));
  double lattice_sum = 0.0;
  double half_lattice_sum = 0.0;  // the layers on one side of a wall, the particle's own included
  for (int k = -reach; k <= reach; ++k) {
    for (int j = -reach; j <= reach; ++j) {
      for (int i = -reach; i <= reach; ++i) {
        const float r2 = static_cast<float>(i * i + j * j + k * k) * spacing * spacing;
        lattice_sum += kernels.poly6(r2);
        if (k >= 0) half_lattice_sum += kernels.poly6(r2);
      }
    }
  }
  c.particle_mass = static_cast<float>(params.rest_density / lattice_sum);
  c.wall_offset = wall_offset_for(kernels, spacing, 1.0 - half_lattice_sum / lattice_sum);
  // The candidate window is 2·reach + 1 cells of h / reach on a side.
  constexpr double cells = NeighbourGrid::kCellsPerRadius;
  const double window = (2.0 * cells + 1.0) / cells * params.kernel_ratio;  // in spacings
  c.max_candidates = static_cast<std::uint32_t>(
      std::ceil(FluidConstants::kCandidatesOverRest * window * window * window));
  const double ratio = params.kernel_ratio;
  c.max_neighbours = static_cast<std::uint32_t>(std::ceil(
      FluidConstants::kNeighboursOverRest * 4.0 / 3.0 * std::numbers::pi * ratio * ratio * ratio));
  return c;
}

}  // namespace fluidcast::sim

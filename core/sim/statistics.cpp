#include "fluidcast/sim/statistics.h"

#include <algorithm>
#include <cmath>

#include "fluidcast/sim/kernels.h"
#include "fluidcast/sim/neighbour_grid.h"

namespace fluidcast::sim {
namespace {

// Each particle's density (measure_densities()), and, where `in_reach` is given, how many others
// lie within kSprayReachSpacings spacings of it.
std::vector<float> measure_neighbourhoods(const ParticleSet& particles, const FluidConstants& fluid,
                                          const Box& tank, std::vector<int>* in_reach) {
  const Kernels kernels(fluid.kernel_radius);
  const Box wall_fluid = fluid.wall_fluid_box(tank);
  const float reach = kSprayReachSpacings * fluid.spacing;
  const float reach2 = reach * reach;
  // poly6 is 0 beyond h: a grid that reaches farther for the spray's count sums the same.
  NeighbourGrid grid(tank, in_reach ? std::max(fluid.kernel_radius, reach) : fluid.kernel_radius);
  ForkJoinPool caller_only(1);
  grid.build(caller_only, particles.position);
  std::vector<glm::vec3> sorted(particles.size());
  const auto order = grid.order();
  for (std::size_t k = 0; k < order.size(); ++k) sorted[k] = particles.position[order[k]];

  std::vector<float> density(particles.size());
  if (in_reach) in_reach->assign(particles.size(), 0);
  for (std::size_t k = 0; k < sorted.size(); ++k) {
    double sum = 0.0;
    int others = -1;  // itself is a candidate too
    grid.for_each_candidate_range(sorted[k], [&](std::uint32_t begin, std::uint32_t end) {
      for (std::uint32_t j = begin; j < end; ++j) {
        const glm::vec3 r = sorted[k] - sorted[j];
        const float r2 = glm::dot(r, r);
        sum += kernels.poly6(r2);
        if (in_reach) others += r2 < reach2 ? 1 : 0;
      }
    });
    const float walls =
        kernels.walls(sorted[k] - wall_fluid.min, wall_fluid.max - sorted[k]).volume;
    density[order[k]] = static_cast<float>(fluid.particle_mass * sum + fluid.rest_density * walls);
    if (in_reach) (*in_reach)[order[k]] = others;
  }
  return density;
}

}  // namespace

std::vector<float> measure_densities(const ParticleSet& particles, const FluidConstants& fluid,
                                     const Box& tank) {
  return measure_neighbourhoods(particles, fluid, tank, nullptr);
}

double surge_front(const ParticleSet& particles, float spacing, const Box& tank) {
  const float band_top = tank.min.y + 2.0f * spacing;
  const float bin_length = 2.0f * spacing;
  const auto bins = static_cast<std::size_t>(std::ceil(tank.size().x / bin_length)) + 1;
  std::vector<float> farthest(bins, -1.0f);  // per bin: largest x from the wall, −1 when empty
  for (const glm::vec3& p : particles.position) {
    if (!is_finite(p) || !tank.contains(p) || p.y > band_top) continue;
    const float x = p.x - tank.min.x;
    const auto bin = std::min(static_cast<std::size_t>(x / bin_length), bins - 1);
    farthest[bin] = std::max(farthest[bin], x);
  }
  double front = 0.0;
  for (const float x : farthest) {
    if (x < 0.0f) break;
    front = x + 0.5 * spacing;  // the water's edge: half a spacing beyond the last centre
  }
  return front;
}

FluidStatistics measure(const ParticleSet& particles, const FluidConstants& fluid,
                        const Box& tank) {
  FluidStatistics s;
  s.particles = particles.size();
  if (particles.size() == 0) return s;
  std::vector<int> in_reach;
  const std::vector<float> density = measure_neighbourhoods(particles, fluid, tank, &in_reach);
  std::size_t spray = 0;
  double error_sum = 0.0;
  glm::dvec3 position_sum(0.0);
  for (std::size_t i = 0; i < particles.size(); ++i) {
    const glm::vec3 x = particles.position[i];
    const glm::vec3 v = particles.velocity[i];
    if (!is_finite(x) || !is_finite(v)) {
      ++s.non_finite;
      continue;
    }
    if (!tank.contains(x)) ++s.outside_tank;
    const double speed2 = glm::dot(v, v);
    s.kinetic_energy += 0.5 * fluid.particle_mass * speed2;
    s.max_speed = std::max(s.max_speed, std::sqrt(speed2));
    const double error = std::max(0.0, density[i] / double(fluid.rest_density) - 1.0);
    s.max_density_error = std::max(s.max_density_error, error);
    error_sum += error;
    position_sum += glm::dvec3(x);
    spray += in_reach[i] < kSprayNeighbours ? 1 : 0;
  }
  const double counted = double(particles.size() - s.non_finite);
  if (counted > 0) {
    s.avg_density_error = error_sum / counted;
    s.centre_of_mass = position_sum / counted;
    s.spray_share = double(spray) / counted;
  }
  s.front_x = surge_front(particles, fluid.spacing, tank);
  return s;
}

}  // namespace fluidcast::sim

// Aggregate measures of a fluid state, computed from positions and velocities alone (with a
// neighbour search of its own), so CPU and GPU solvers are measured the same way.
#pragma once

#include <cstddef>
#include <glm/glm.hpp>
#include <vector>

#include "fluidcast/sim/fluid_constants.h"
#include "fluidcast/sim/particles.h"

namespace fluidcast::sim {

// Spray: a particle with fewer than kSprayNeighbours others within kSprayReachSpacings particle
// spacings of it (about 33 inside the water, 8 in a sheet one particle thick) is a droplet, part of
// a thread or of a sheet torn apart, not water. The renderer draws such particles as spray by
// default (render::SsfrStyle::spray_neighbours).
inline constexpr int kSprayNeighbours = 6;
inline constexpr float kSprayReachSpacings = 2.0f;

struct FluidStatistics {
  std::size_t particles = 0;
  double kinetic_energy = 0;       // J, Σ ½ m |v|²
  double max_density_error = 0;    // max over particles of max(0, ρ/ρ0 − 1)
  double avg_density_error = 0;    // mean over particles of max(0, ρ/ρ0 − 1)
  double front_x = 0;              // m from the tank's left wall: surge_front()
  glm::dvec3 centre_of_mass{0.0};  // m
  double max_speed = 0;            // m/s
  double spray_share = 0;          // of the finite particles, the fraction that are spray
  std::size_t outside_tank = 0;    // particles whose centre is outside the tank
  std::size_t non_finite = 0;      // particles with a NaN or infinite position or velocity
};

// ρ_i = m Σ_j W_poly6(|x_i − x_j|) over all particles within h, itself included, plus what the
// tank's walls add (Kernels::walls): the density each solver holds at ρ0.
std::vector<float> measure_densities(const ParticleSet& particles, const FluidConstants& fluid,
                                     const Box& tank);

// The surge front: how far from the tank's left wall the water on the floor reaches, robust to
// droplets. The floor band (centres within two spacings of the floor) is cut into bins two
// spacings long along x; from the wall, bins holding a particle are followed until the first
// empty one, and the front lies half a spacing beyond the largest x of a particle in the last of
// them (the water's edge, not the last centre). A droplet ahead of
// the tongue, with an empty bin between, is not the front. 0 when no particle touches the floor
// at the wall.
double surge_front(const ParticleSet& particles, float spacing, const Box& tank);

FluidStatistics measure(const ParticleSet& particles, const FluidConstants& fluid, const Box& tank);

}  // namespace fluidcast::sim

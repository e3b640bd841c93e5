// The constants a simulation derives from its particle spacing and tunables.
#pragma once

#include "fluidcast/sim/particles.h"
#include "fluidcast/sim/solver_params.h"

namespace fluidcast::sim {

struct FluidConstants {
  float spacing = 0.0f;        // d, m
  float kernel_radius = 0.0f;  // h = kernel_ratio · d, m
  float particle_mass = 0.0f;  // kg
  float rest_density = 0.0f;   // ρ0, kg/m³
  // How far behind each tank wall the walls' fluid at rest begins (Kernels::wall_volume), m: where
  // a cubic lattice's first layer, half a spacing from the wall, sums to exactly ρ0 as the bulk
  // does. Begun at the wall itself, it made that layer read 2.6 % over ρ0 at h = 2d, and every
  // fluid started by pushing itself off the walls (OVERVIEW.md, choices).
  float wall_offset = 0.0f;
  // Candidate neighbours examined per particle, at most: kCandidatesOverRest times what a
  // particle inside a fluid at rest density has in its 5×5×5 cells. A clump (a pour, a finger
  // pushing water into a corner) then costs each particle a bounded amount, not the clump's size;
  // a fluid near rest never reaches it.
  std::uint32_t max_candidates = 0;
  static constexpr double kCandidatesOverRest = 4.0;
  // Neighbours listed per particle, at most: kNeighboursOverRest times what a fluid at rest has
  // within h (the kernel's sphere over a spacing's cube). The GPU keeps a list of this length per
  // particle; a particle with more is in a clump twice as dense as water, whose first ones
  // already push it apart.
  std::uint32_t max_neighbours = 0;
  static constexpr double kNeighboursOverRest = 2.0;

  float particle_radius() const { return 0.5f * spacing; }
  float rest_volume() const { return particle_mass / rest_density; }
  // What the walls' fluid at rest lies outside of: `tank` grown by wall_offset.
  Box wall_fluid_box(const Box& tank) const {
    return {tank.min - glm::vec3(wall_offset), tank.max + glm::vec3(wall_offset)};
  }
};

// The mass makes a cubic lattice of spacing d sum to exactly ρ0 with the poly6 kernel, so a scene
// starts at rest density instead of a few percent off (ρ0·d³ would be, since the discrete kernel
// sum is not exactly 1/d³); the wall offset does the same for the lattice's layer at a wall.
FluidConstants derive_fluid_constants(float spacing, const SolverParams& params);

}  // namespace fluidcast::sim

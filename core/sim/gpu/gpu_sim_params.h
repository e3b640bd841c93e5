// C++ mirror of shaders/common/sim_params.glsl (std430): the parameter block of the GPU solvers
// and the push constants of each pass. The static_asserts pin every offset to the GLSL layout.
#pragma once

#include <vulkan/vulkan.h>

#include <cstddef>
#include <cstdint>
#include <glm/glm.hpp>

#include "fluidcast/sim/solver.h"

namespace fluidcast::sim::gpu_solver {

inline constexpr std::uint32_t kSolverPbf = 0;  // SOLVER_PBF
inline constexpr std::uint32_t kSolverSph = 1;  // SOLVER_SPH
static_assert(kMaxColliders == 16, "MAX_COLLIDERS in sim_params.glsl");

struct SimParams {
  VkDeviceAddress position, velocity, id;
  VkDeviceAddress sorted_position, sorted_velocity, sorted_id;
  VkDeviceAddress predicted, iterate, iterate_scalar, vorticity;
  VkDeviceAddress density, acceleration;
  VkDeviceAddress order, cell_start, sorted_cell, cell_of, rank, stats, density_ratio;
  VkDeviceAddress neighbours, neighbour_count;

  alignas(16) glm::vec4 wall_fluid_min, wall_fluid_max, inner_min, inner_max, gravity;
  glm::ivec4 grid_dims;
  glm::vec4 grid_origin;

  std::uint32_t solver, particle_count, collider_count;
  float h, h2, poly6, spiky, viscosity_laplacian, mass, rest_density, inv_rest_density, rest_volume,
      particle_radius;
  float relaxation_epsilon, scorr_scale, inv_w_dq, scorr_exponent, vorticity_epsilon, xsph;
  float tait_stiffness, tait_exponent, sph_viscosity, artificial_viscosity, softening;
  float substep_travel;
  std::uint32_t max_candidates;
  float max_acceleration;
  std::uint32_t max_neighbours;
  float wall_reach;
  float stiffness_share, pressed_from, pressed_span;
  float max_speed;

  alignas(16) glm::vec4 collider_sphere[kMaxColliders];
  glm::vec4 collider_velocity[kMaxColliders];
};
static_assert(offsetof(SimParams, stats) == 17 * 8);
static_assert(offsetof(SimParams, density_ratio) == 18 * 8);
static_assert(offsetof(SimParams, neighbour_count) == 20 * 8);
static_assert(offsetof(SimParams, wall_fluid_min) == 176);
static_assert(offsetof(SimParams, grid_dims) == 176 + 5 * 16);
static_assert(offsetof(SimParams, grid_origin) == 176 + 6 * 16);
static_assert(offsetof(SimParams, solver) == 176 + 7 * 16);
static_assert(offsetof(SimParams, h) == 176 + 7 * 16 + 12);
static_assert(offsetof(SimParams, relaxation_epsilon) == 176 + 7 * 16 + 13 * 4);
static_assert(offsetof(SimParams, softening) == 176 + 7 * 16 + 23 * 4);
static_assert(offsetof(SimParams, substep_travel) == 176 + 7 * 16 + 24 * 4);
static_assert(offsetof(SimParams, max_candidates) == 176 + 7 * 16 + 25 * 4);
static_assert(offsetof(SimParams, max_acceleration) == 176 + 7 * 16 + 26 * 4);
static_assert(offsetof(SimParams, max_neighbours) == 176 + 7 * 16 + 27 * 4);
static_assert(offsetof(SimParams, wall_reach) == 176 + 7 * 16 + 28 * 4);
static_assert(offsetof(SimParams, pressed_span) == 176 + 7 * 16 + 31 * 4);
static_assert(offsetof(SimParams, max_speed) == 176 + 7 * 16 + 32 * 4);
static_assert(offsetof(SimParams, collider_sphere) == 176 + 7 * 16 + 36 * 4);
static_assert(offsetof(SimParams, collider_velocity) ==
              offsetof(SimParams, collider_sphere) + kMaxColliders * 16);
static_assert(sizeof(SimParams) % 4 == 0, "vkCmdUpdateBuffer takes whole words");

// Mirrors the SimPass push constants.
struct SimPass {
  VkDeviceAddress params;
  float dt;
  float time_into_step;
  std::uint32_t last_substep;
  float correction_weight;
  std::uint32_t write_velocity;
};
static_assert(offsetof(SimPass, dt) == 8 && offsetof(SimPass, last_substep) == 16 &&
              offsetof(SimPass, correction_weight) == 20 &&
              offsetof(SimPass, write_velocity) == 24);

// The statistics a step leaves in P.stats, read back by the host.
enum StatsSlot : std::uint32_t {
  kLargestSpeed2 = 0,        // bits of the largest |v|²
  kLargestAcceleration = 1,  // bits of the largest |a| (SPH)
  kCompressionSum = 2,       // PBF: Σ max(ρ/ρ0 − 1, 0), low word, in units of kCompressionUnit
  kCompressionSumHigh = 3,   // and its high word
  kLargestWallApproach = 4,  // PBF: bits of the largest wall_approach (substeps.h)
  kStatsSlots = 5,
};
inline constexpr double kCompressionUnit = 1.0 / (1 << 20);

}  // namespace fluidcast::sim::gpu_solver

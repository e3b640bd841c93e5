// How finely a step is cut, shared by the CPU and GPU solvers.
#pragma once

#include "fluidcast/sim/solver_params.h"

namespace fluidcast::sim {

// PBF: substeps of a step of `step` seconds so that nothing moves more than cfl_number · h in one, the fluid (its largest
// speed plus what gravity adds over the step) or a collider. Non-finite speeds give max_substeps.
int pbf_substep_count(float step, float largest_speed, float largest_collider_speed, float gravity,
                      const SolverParams& params, float kernel_radius);

// SPH: the longest stable substep: the CFL bound with the speed of sound, the force bound
// 0.25 √(h / |a|max), and the viscous bound 0.125 h² / ν.
float sph_stable_substep(float largest_speed, float largest_acceleration,
                         const SolverParams& params, float kernel_radius);

}  // namespace fluidcast::sim

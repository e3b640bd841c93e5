#include "fluidcast/sim/solver_params.h"

#include <sstream>
#include <string>

#include "substeps.h"

namespace fluidcast::sim {

const std::vector<ParamSpec<SolverParams>>& solver_param_specs() {
  using P = SolverParams;
  static const std::string travel = [] {
    std::ostringstream text;
    text << "PBF: most a particle or collider may move in one substep, as a fraction of h; a "
            "particle flung faster is slowed to it. Above 1 particles begin to pass through each "
            "other. Toward a tank wall it may close by this fraction of "
         << PbfSubsteps::kWallShareOfSpacing
         << " d (d the particle spacing): a layer that moved a whole spacing would land on the "
            "one the wall holds";
    return text.str();
  }();
  static const std::vector<ParamSpec<P>> specs = {
      {"time-step", "s", "Simulated time advanced by one step", &P::time_step, 1e-5, 0.05},
      {"rest-density", "kg/m³", "Rest density ρ0 of the fluid", &P::rest_density, 100, 20000},
      {"kernel-ratio", "1",
       "Kernel radius h over particle spacing d; 2 gives about 33 neighbours at rest. The work of "
       "every pass grows with its cube, and so does the GPU's list of neighbours (room for twice "
       "as many as at rest, 4 bytes each, and its length: 276 bytes a particle at 2)",
       &P::kernel_ratio, 1.5, 4},
      {"max-particles", "1", "Most particles a simulation may hold (add_particles refuses more)",
       &P::max_particles, 1, kMostParticles},
      {"threads", "1", "Worker threads; 0 means one per core", &P::threads, 0, 256},
      {"max-substeps", "1",
       "Most substeps one step may take; past it the CFL bound is exceeded rather than the "
       "step slowed further",
       &P::max_substeps, 1, 100000},
      {"iterations", "1", "PBF: Jacobi iterations of the density constraint per substep",
       &P::iterations, 1, 100},
      {"pbf-jacobi-damping", "1",
       "PBF: d: the first Jacobi iteration's position corrections are applied by 1 + d, the "
       "last's by 1 − d (one iteration: in full). Iterations in full leave a particle-scale "
       "oscillation, each particle pushed about as far past its neighbours' target as it began "
       "short of it; 0.5 cancels it, while the weights' sum keeps the smooth error corrected as "
       "in full: a resting pool's largest density error 2.0 → 1.3 %, a dam break's 14–17 → "
       "9–12 %, substeps as many or fewer; 0 applies every iteration in full",
       &P::pbf_jacobi_damping, 0, 0.5},
      {"pbf-travel", "1", travel, &P::pbf_travel, 0.05, 2},
      {"pbf-density-tolerance", "1",
       "PBF: average compression max(ρ/ρ0 − 1, 0) a step may leave, walls included; a step "
       "that left more makes the next ones take shorter substeps, and a fluid just loaded (a "
       "scene's start, a reset, a snapshot) starts with substeps short enough that its own "
       "weight would compress it at its foot by no more than this. Only this bound stiffens the "
       "fluid: substeps cut finer for travel, walls or a finger, in slow motion too, weaken "
       "their corrections to keep the stiffness of those this bound asks for, except where a "
       "particle is compressed past 3 times this (in full past 6)",
       &P::pbf_density_tolerance, 1e-4, 0.1},
      {"pbf-max-acceleration", "m/s²",
       "PBF: most the density corrections may accelerate a particle: the velocity a substep's "
       "corrections add is capped at this times the substep, while the positions are not. "
       "Bounds the energy a compressed fluid releases when its substeps shorten (as "
       "NVIDIA FleX's maxAcceleration); the default leaves a dam break's wall impact as it was",
       &P::pbf_max_acceleration, 10, 100000},
      {"relaxation", "1",
       "PBF: constraint force mixing ε, as a fraction of Σ|∇C|² of a particle at rest",
       &P::relaxation, 1e-6, 10},
      {"scorr-strength", "1", "PBF: artificial pressure k (s_corr), against clustering",
       &P::scorr_strength, 0, 1},
      {"scorr-exponent", "1", "PBF: artificial pressure exponent n", &P::scorr_exponent, 1, 8},
      {"scorr-distance", "1", "PBF: artificial pressure reference distance Δq, as a fraction of h",
       &P::scorr_distance, 0.01, 0.9},
      {"vorticity", "m/s",
       "PBF: vorticity confinement strength ε (acceleration ε·N×ω), applied once a step over its "
       "whole length",
       &P::vorticity, 0, 1},
      {"xsph-viscosity", "1",
       "PBF: XSPH velocity smoothing c a substep, applied once a step as 1 − (1 − c)^substeps",
       &P::xsph_viscosity, 0, 1},
      {"cfl-number", "1",
       "SPH: substeps keep (c+|v|max)·Δt ≤ cfl·h, besides the force and viscosity bounds",
       &P::cfl_number, 0.05, 1},
      {"sound-speed", "m/s", "SPH: numerical speed of sound; stiffness B = ρ0 c²/γ",
       &P::sound_speed, 1, 500},
      {"tait-exponent", "1", "SPH: exponent γ of the Tait equation of state", &P::tait_exponent, 1,
       7},
      {"sph-viscosity", "Pa·s", "SPH: dynamic viscosity μ (Müller 2003 viscosity kernel)",
       &P::sph_viscosity, 0, 100},
      {"artificial-viscosity", "1",
       "SPH: Monaghan's artificial viscosity α, which damps the pressure waves of a stiff fluid",
       &P::artificial_viscosity, 0, 1},
  };
  return specs;
}

void validate(const SolverParams& params) { validate(params, solver_param_specs()); }

}  // namespace fluidcast::sim

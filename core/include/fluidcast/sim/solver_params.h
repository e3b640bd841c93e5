// The tunables of both solvers, in SI units. Each is declared with its range in
// solver_param_specs().
#pragma once

#include <vector>

#include "fluidcast/sim/param_spec.h"
#include "fluidcast/sim/particles.h"

namespace fluidcast::sim {

struct SolverParams {
  // Shared by PBF and SPH.
  float time_step = 1.0f / 120.0f;  // s, one step() advances this much
  float rest_density = 1000.0f;     // kg/m³
  float kernel_ratio = 2.0f;        // kernel radius h over particle spacing d
  int max_particles = 1 << 20;      // cap for add_particles
  int threads = 0;  // a CPU solver's own pool (0: one per core; make_cpu_solver may share one)
  int max_substeps = 256;  // a step never splits into more substeps than this

  // PBF (Macklin & Müller 2013).
  int iterations = 4;
  float pbf_jacobi_damping = 0.5f;  // d: the first iteration's Δp by 1 + d, the last's by 1 − d
  float pbf_travel = 1.0f;  // most a particle or collider moves in one substep, as a fraction of h
  float pbf_density_tolerance = 0.01f;  // average ρ/ρ0 − 1 a step may leave, walls included
  float pbf_max_acceleration =
      300.0f;                    // m/s², most the density corrections may accelerate a particle
  float relaxation = 0.01f;      // ε as a fraction of the rest-state Σ|∇C|²
  float scorr_strength = 0.1f;   // k of the artificial pressure
  float scorr_exponent = 4.0f;   // n
  float scorr_distance = 0.2f;   // Δq / h
  float vorticity = 0.02f;       // ε of vorticity confinement, m/s
  float xsph_viscosity = 0.05f;  // c of XSPH

  // SPH (weakly compressible; Müller et al. 2003 kernels, Tait equation of state).
  float cfl_number = 0.4f;             // substeps keep (c+|v|max)·Δt ≤ cfl·h
  float sound_speed = 20.0f;           // m/s, sets the stiffness B = ρ0 c² / γ
  float tait_exponent = 7.0f;          // γ
  float sph_viscosity = 0.05f;         // dynamic viscosity μ, Pa·s
  float artificial_viscosity = 0.25f;  // α of Monaghan's artificial viscosity
};

const std::vector<ParamSpec<SolverParams>>& solver_param_specs();

// Throws ParamError naming the first bad tunable.
void validate(const SolverParams& params);

}  // namespace fluidcast::sim

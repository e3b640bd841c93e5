// Constants of the PBF density constraint, derived once from the tunables and the particle
// spacing, and shared by the CPU and GPU solvers.
#pragma once

#include "fluidcast/sim/fluid_constants.h"
#include "fluidcast/sim/solver_params.h"

namespace fluidcast::sim {

struct PbfConstants {
  float relaxation_epsilon = 0.0f;  // ε, absolute: relaxation × Σ|∇C|² at rest
  float scorr_scale = 0.0f;         // k / Σ|∇C|² at rest
  float inv_w_dq = 0.0f;            // 1 / W(Δq)
};

// ε and k are given relative to Σ_j |∇_j C_i|² of a particle inside the cubic lattice at rest, so
// that they mean the same at every particle spacing.
PbfConstants derive_pbf_constants(const SolverParams& params, const FluidConstants& fluid);

// The share of iteration `iteration`'s position corrections applied (weighted Jacobi): the last by
// 1 − pbf_jacobi_damping, which damps the particle-scale oscillation that iterations in full leave
// (0.5 cancels it); the first by 1 + pbf_jacobi_damping, so that the weights sum as in full and
// the smooth part of the error is corrected as much. One iteration is applied in full: it has
// nothing to be balanced against.
float pbf_correction_weight(const SolverParams& params, int iteration);

// XSPH's c for a step of `substeps` substeps. XSPH and vorticity confinement, filters of the
// velocity, run once a step, on its last substep (with the compression measured there, they were
// a third of a 1M substep's GPU time on an H200), with c compounded over the substeps,
// 1 − (1 − c)^substeps, about as much smoothing as one at each substep gave, and the confinement
// over the whole step. A 216k dam break's first 0.5 s took the same 344 substeps, its largest
// density error 6.4 → 6.1 %, spray 0.131 → 0.128 %
// (bench/results/velocity-filters-once-a-step-cpu-2026-11-29.md).
float pbf_step_xsph(const SolverParams& params, int substeps);

}  // namespace fluidcast::sim

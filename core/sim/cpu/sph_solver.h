// Weakly compressible SPH: the kernels and viscosity of Müller, Charypar & Gross, "Particle-based
// fluid simulation for interactive applications", SCA 2003, with the Tait equation of state and
// symmetric pressure force of Becker & Teschner, "Weakly compressible SPH for free surface flows",
// SCA 2007, and Monaghan's artificial viscosity. Each step is split into substeps bounded by the
// CFL condition, the largest acceleration and the viscous diffusion limit.
#pragma once

#include "cpu/cpu_solver.h"

namespace fluidcast::sim::cpu {

// p = B ((ρ/ρ0)^γ − 1), B = ρ0 c² / γ, clamped at zero: no tension at the free surface.
float tait_pressure(float density, const SolverParams& params);

class SphSolver final : public CpuSolver {
 public:
  SphSolver(Scene scene, const SolverParams& params, std::shared_ptr<ForkJoinPool> pool);
  SolverKind kind() const override { return SolverKind::sph; }

 private:
  int substeps_for(float seconds) override;
  int advance(float seconds, int substeps) override;
  void compute_densities_and_pressures();
  // Returns the largest acceleration magnitude.
  float compute_accelerations();
  float stable_substep(float max_acceleration);
  void integrate(float dt);

  std::vector<float> density_, pressure_, chunk_max_acceleration_;
  float min_substep_;                   // time_step / max_substeps
  float last_max_acceleration_ = 0.0f;  // of the newest substep, for substeps_for()
  std::vector<glm::vec3> acceleration_;
};

}  // namespace fluidcast::sim::cpu

// Shared by the solver tests: build a small scene, run it, and check the invariants every state
// must keep (finite, inside the tank, no particle lost).
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "../gpu/gpu_test_support.h"
#include "fluidcast/sim/solver.h"
#include "fluidcast/sim/statistics.h"

namespace fluidcast::sim::testing {

enum class Backend { cpu, gpu };

inline std::unique_ptr<Solver> make_solver(SolverKind kind, SceneKind scene, int particles,
                                           SolverParams params = {},
                                           Backend backend = Backend::cpu) {
  SceneParams s;
  s.kind = scene;
  s.particles = particles;
  if (backend == Backend::gpu) {
    return make_gpu_solver(kind, fluidcast::testing::test_context(), build_scene(s), params);
  }
  if (params.threads == 0) params.threads = 2;
  return make_cpu_solver(kind, build_scene(s), params);
}

inline void run_for(Solver& solver, double seconds) {
  const auto steps = static_cast<int>(std::lround(seconds / solver.params().time_step));
  for (int k = 0; k < steps; ++k) solver.step();
}

inline FluidStatistics stats(const Solver& solver) {
  return measure(solver.snapshot(), solver.fluid(), solver.tank());
}

inline void expect_sound(const Solver& solver, std::size_t expected_particles) {
  const FluidStatistics s = stats(solver);
  EXPECT_EQ(s.particles, expected_particles);
  EXPECT_EQ(s.non_finite, 0u);
  EXPECT_EQ(s.outside_tank, 0u);
  EXPECT_TRUE(std::isfinite(s.kinetic_energy));
}

// A pool left to settle for `settle` seconds, then watched every 0.1 s for `watch` seconds.
struct PoolAtRest {
  double worst_density_error = 0.0;  // over the watch
  double worst_drift = 0.0;          // m, of the centre of mass from where it settled
  double settled_kinetic_energy = 0.0, final_kinetic_energy = 0.0;  // J
  double final_rms_speed = 0.0;                                     // m/s
};

inline PoolAtRest watch_pool_at_rest(Solver& solver, double settle, double watch) {
  const std::size_t particles = solver.particle_count();
  run_for(solver, settle);
  const FluidStatistics settled = stats(solver);
  PoolAtRest result;
  result.settled_kinetic_energy = settled.kinetic_energy;
  for (int k = 0; k < static_cast<int>(std::lround(watch / 0.1)); ++k) {
    run_for(solver, 0.1);
    const FluidStatistics s = stats(solver);
    result.worst_density_error = std::max(result.worst_density_error, s.max_density_error);
    result.worst_drift =
        std::max(result.worst_drift, glm::length(s.centre_of_mass - settled.centre_of_mass));
    expect_sound(solver, particles);
  }
  const FluidStatistics last = stats(solver);
  result.final_kinetic_energy = last.kinetic_energy;
  result.final_rms_speed =
      std::sqrt(2.0 * last.kinetic_energy / (last.particles * solver.fluid().particle_mass));
  std::printf("pool at rest (%s): max density error %.4f, drift %.2e m, rms speed %.4f m/s\n",
              std::string(to_string(solver.kind())).c_str(), result.worst_density_error,
              result.worst_drift, result.final_rms_speed);
  return result;
}

inline std::string solver_name(const ::testing::TestParamInfo<SolverKind>& info) {
  return std::string(to_string(info.param));
}

}  // namespace fluidcast::sim::testing

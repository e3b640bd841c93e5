// Shared by the solver tests: build a small scene, run it, and check the invariants every state
// must keep (finite, inside the tank, no particle lost).
#pragma once

#include <gtest/gtest.h>

#include <cmath>

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

inline std::string solver_name(const ::testing::TestParamInfo<SolverKind>& info) {
  return std::string(to_string(info.param));
}

}  // namespace fluidcast::sim::testing

// Shared by the solver tests: build a small scene, run it, and check the invariants every state
// must keep (finite, inside the tank, no particle lost).
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <set>
#include <string>

#include "../gpu/gpu_test_support.h"
#include "fluidcast/sim/solver.h"
#include "fluidcast/sim/statistics.h"

namespace fluidcast::sim::testing {

enum class Backend { cpu, gpu };

inline std::unique_ptr<Solver> make_solver(SolverKind kind, Scene scene, SolverParams params = {},
                                           Backend backend = Backend::cpu) {
  if (backend == Backend::gpu) {
    return make_gpu_solver(kind, fluidcast::testing::test_context(), std::move(scene), params);
  }
  if (params.threads == 0) params.threads = 2;
  return make_cpu_solver(kind, std::move(scene), params);
}

inline std::unique_ptr<Solver> make_solver(SolverKind kind, const SceneParams& scene,
                                           SolverParams params = {},
                                           Backend backend = Backend::cpu) {
  return make_solver(kind, build_scene(scene), params, backend);
}

inline std::unique_ptr<Solver> make_solver(SolverKind kind, SceneKind scene, int particles,
                                           SolverParams params = {},
                                           Backend backend = Backend::cpu) {
  SceneParams s;
  s.kind = scene;
  s.particles = particles;
  return make_solver(kind, s, params, backend);
}

inline void run_for(Solver& solver, double seconds) {
  const auto steps = static_cast<int>(std::lround(seconds / solver.params().time_step));
  for (int k = 0; k < steps; ++k) solver.step();
}

// The largest distance between one particle's places in two sets of the same particles (matched
// by id).
inline double farthest_apart_by_id(const ParticleSet& a, const ParticleSet& b) {
  EXPECT_EQ(a.size(), b.size());
  std::map<std::uint32_t, glm::vec3> position_in_a;
  for (std::size_t i = 0; i < a.size(); ++i) position_in_a[a.id[i]] = a.position[i];
  double farthest = 0.0;
  for (std::size_t i = 0; i < b.size(); ++i) {
    farthest = std::max<double>(farthest, glm::length(b.position[i] - position_in_a.at(b.id[i])));
  }
  return farthest;
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

// A pool as deep as a 1M-particle one (57 layers of 5.2 mm) in a tank narrow enough to hold it in
// 2600 particles, settled for 1 s, then watched for 60 steps: how far its centre of mass rose and
// fell (seen every third step, so that a GPU's steps still run in flight between), and how many
// substep counts its steps took. Under a substep rule that looked at the last step alone it
// bounced for good: 5.7 mm and 6 counts on the CPU, 10.8 mm and 10 on lavapipe's GPU (the H200
// saw the 1M pool do it: its average density error swung between 0.01 % and 1.7 %).
struct DeepPoolWatch {
  double centre_of_mass_range = 0.0;  // m, in height
  std::size_t substep_counts = 0;     // distinct counts a step took
};

inline DeepPoolWatch watch_deep_pool(Backend backend) {
  SceneParams scene;
  scene.kind = SceneKind::pool;
  scene.particles = 2600;
  scene.tank_length = 0.06f;
  scene.depth = 0.02f;
  auto solver = make_solver(SolverKind::pbf, scene, {}, backend);
  run_for(*solver, 1.0);
  double lowest = std::numeric_limits<double>::infinity(), highest = -lowest;
  std::set<int> counts;
  for (int step = 0; step < 60; ++step) {
    counts.insert(solver->step());
    if (step % 3 != 2) continue;
    const double height = stats(*solver).centre_of_mass.y;
    lowest = std::min(lowest, height);
    highest = std::max(highest, height);
  }
  expect_sound(*solver, 2600);
  std::printf("deep pool: centre of mass within %.2f mm, %zu substep counts\n",
              1000.0 * (highest - lowest), counts.size());
  return {highest - lowest, counts.size()};
}

// As deep as a 1M-particle dam break's column, 175 particles, in a tank 3 cm thin: 100,000.
inline SceneParams deep_thin_column() {
  SceneParams scene;
  scene.kind = SceneKind::dam_break;
  scene.particles = 100000;
  scene.depth = 0.03f;
  return scene;
}

// The deep thin column, ten steps from rest. Compression builds at the column's foot when the
// substep rule hears of it late (a GPU's steps in flight) or allows much of it (`tolerance`);
// released over ever shorter substeps it came back as a burst: particles at 14–17 m/s along the
// walls by t = 0.083 s and 2.2–4.3 times the kinetic energy the fall had released. The fluid may
// only turn the potential energy it lost into motion; PBF is not strictly dissipative (s_corr
// pushes particles apart), and runs that do not burst measure 0.9–1.36 times, so the bound is 1.5.
struct DeepColumnEnergy {
  double kinetic = 0.0;   // J, at the end
  double released = 0.0;  // J, by the fall: M g Δy of the centre of mass
};

inline DeepColumnEnergy run_deep_thin_column(Backend backend, float tolerance) {
  SolverParams params;
  params.pbf_density_tolerance = tolerance;
  auto solver = make_solver(SolverKind::pbf, deep_thin_column(), params, backend);
  const FluidStatistics start = stats(*solver);
  for (int k = 0; k < 10; ++k) solver->step();
  const FluidStatistics end = stats(*solver);
  expect_sound(*solver, 100000);
  const double mass = static_cast<double>(end.particles) * solver->fluid().particle_mass;
  DeepColumnEnergy e;
  e.kinetic = end.kinetic_energy;
  e.released =
      mass * glm::length(solver->gravity()) * (start.centre_of_mass.y - end.centre_of_mass.y);
  std::printf("deep thin column: kinetic energy %.3f J, released %.3f J, largest speed %.2f m/s\n",
              e.kinetic, e.released, end.max_speed);
  return e;
}

inline std::string solver_name(const ::testing::TestParamInfo<SolverKind>& info) {
  return std::string(to_string(info.param));
}

}  // namespace fluidcast::sim::testing

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <vector>

#include "pbf_constants.h"
#include "solver_test_support.h"

namespace fluidcast::sim {
namespace {

using testing::make_solver;
using testing::run_for;
using testing::stats;

// A pool settles and then stays at rest: density held within 1 % by 10 iterations, nothing
// leaves, the centre of mass does not drift by more than a tenth of a particle spacing, and the
// small slosh left from settling (the tank's first mode, period ≈ 1.9 s) only decays.
TEST(Pbf, PoolAtRestStaysAtRest) {
  SolverParams params;
  params.iterations = 10;
  auto solver = make_solver(SolverKind::pbf, SceneKind::pool, 2000, params);
  const testing::PoolAtRest pool = testing::watch_pool_at_rest(*solver, 1.0, 1.0);
  EXPECT_LT(pool.worst_density_error, 0.01);
  EXPECT_LT(pool.worst_drift, 0.1 * solver->fluid().spacing);
  EXPECT_LT(pool.final_kinetic_energy, pool.settled_kinetic_energy);
  EXPECT_LT(pool.final_rms_speed, 0.05);
}

// Jacobi iterations applied in full leave each particle about as far past its target as it began
// short of it; the last one applied by half (and the first by 1.5) cancels that. With the default
// 4 iterations the settled 2000-particle pool's largest density error measured 2.1 % in full and
// 1.2 % damped.
TEST(Pbf, JacobiDampingLowersTheLargestDensityError) {
  const auto worst_with = [](float damping) {
    SolverParams params;
    params.pbf_jacobi_damping = damping;
    auto solver = make_solver(SolverKind::pbf, SceneKind::pool, 2000, params);
    return testing::watch_pool_at_rest(*solver, 0.5, 1.0).worst_density_error;
  };
  const double in_full = worst_with(0.0f);
  const double damped = worst_with(0.5f);
  EXPECT_LT(damped, 0.85 * in_full);
  EXPECT_LT(damped, 0.02);
}

TEST(Pbf, JacobiDampingWeighsTheFirstAndLastIterationsAndKeepsTheirSum) {
  SolverParams params;
  params.pbf_jacobi_damping = 0.5f;
  params.iterations = 4;
  const std::vector<float> four = {
      pbf_correction_weight(params, 0), pbf_correction_weight(params, 1),
      pbf_correction_weight(params, 2), pbf_correction_weight(params, 3)};
  EXPECT_EQ(four, (std::vector<float>{1.5f, 1.0f, 1.0f, 0.5f}));
  for (const float damping : {0.0f, 0.25f, 0.5f}) {
    params.pbf_jacobi_damping = damping;
    for (int iterations = 2; iterations <= 5; ++iterations) {
      params.iterations = iterations;
      float sum = 0.0f;
      for (int k = 0; k < iterations; ++k) sum += pbf_correction_weight(params, k);
      EXPECT_EQ(sum, static_cast<float>(iterations)) << "damping " << damping;
    }
  }
  params.iterations = 1;
  EXPECT_EQ(pbf_correction_weight(params, 0), 1.0f);
}

// XSPH and vorticity confinement run once a step, on its last substep (pbf_step_xsph): from a
// stirred pool, a step cut into four substeps changes the velocity as four steps of one substep
// do, each of which applies them. The two cuts' velocities differ by less than 0.57 of what the
// filters change (0.28 of it with XSPH, 0.47 with the confinement, whose direction turns with
// the curl's field); seen failing with XSPH's c applied once uncompounded (0.68) and with the
// confinement over the last substep alone (0.73). It checks the rule's equivalence, not the work
// saved: the filters at every substep, as before, pass it too.
TEST(Pbf, VelocityFiltersOnceAStepActAsAtEverySubstep) {
  struct Filters {
    float xsph_viscosity, vorticity;
  };
  for (const Filters filters : {Filters{0.2f, 0.0f}, Filters{0.0f, 1.0f}}) {
    SolverParams params;
    params.xsph_viscosity = filters.xsph_viscosity;
    params.vorticity = filters.vorticity;
    // The least tolerance and 3 iterations: the density bound alone cuts the step compared into
    // 5 substeps, so that both cuts are as stiff (PbfSubsteps::stiffness_substep).
    params.pbf_density_tolerance = 0.0001f;
    params.iterations = 3;
    auto settling = make_solver(SolverKind::pbf, SceneKind::pool, 2000, params);
    // Settled: a fresh lattice's corrections would come back as velocity that drowns the
    // filters'.
    for (int k = 0; k < 120; ++k) settling->step();
    Scene stirred = settling->scene();
    stirred.particles = settling->snapshot();
    std::uint32_t seed = 12345u;
    const auto next = [&seed] {
      seed = seed * 1664525u + 1013904223u;
      return static_cast<float>(seed >> 8) / static_cast<float>(1u << 24) - 0.5f;
    };
    for (glm::vec3& v : stirred.particles.velocity) v += 0.1f * glm::vec3(next(), next(), next());

    // Each particle's velocity by id after 1/120 s in `steps` steps of `substeps`.
    const auto velocities_after = [&](const SolverParams& with, int steps, int substeps) {
      auto solver = make_solver(SolverKind::pbf, stirred, with);
      for (int k = 0; k < steps; ++k) {
        solver->step(with.time_step / static_cast<float>(steps), substeps);
      }
      const ParticleSet state = solver->snapshot();
      std::vector<glm::vec3> by_id(state.size());
      for (std::size_t i = 0; i < state.size(); ++i) by_id.at(state.id[i]) = state.velocity[i];
      return by_id;
    };
    const auto rms_difference = [](const std::vector<glm::vec3>& a,
                                   const std::vector<glm::vec3>& b) {
      double sum = 0.0;
      for (std::size_t i = 0; i < a.size(); ++i) sum += glm::dot(a[i] - b[i], a[i] - b[i]);
      return std::sqrt(sum / static_cast<double>(a.size()));
    };
    SolverParams unfiltered = params;
    unfiltered.xsph_viscosity = 0.0f;
    unfiltered.vorticity = 0.0f;
    const auto four_of_one = velocities_after(params, 4, 1);
    const double filtered = rms_difference(four_of_one, velocities_after(unfiltered, 4, 1));
    const double cut_apart = rms_difference(velocities_after(params, 1, 4), four_of_one);
    std::printf("XSPH %g, vorticity %g: the filters change the velocity by %.3g m/s (rms), the "
                "cuts differ by %.3g\n",
                filters.xsph_viscosity, filters.vorticity, filtered, cut_apart);
    EXPECT_LT(cut_apart, 0.57 * filtered);
  }
}

// This pool sits where one substep of 4 iterations leaves just over the density tolerance and two
// leave a quarter of it. Substeps that lengthened to the tolerance's edge cycled there: four steps
// of one substep in every fourteen, the pool compressing in each (largest density error 1 → 3 %)
// and springing back. Lengthened with a margin, the count holds.
TEST(Pbf, RestingPoolHoldsItsSubstepCount) {
  auto solver = make_solver(SolverKind::pbf, SceneKind::pool, 8000);
  run_for(*solver, 1.0);
  int changes = 0;
  std::uint64_t previous = 0;
  double worst_density_error = 0.0;
  for (int step = 0; step < 60; ++step) {
    const std::uint64_t before = solver->stage_times().substeps;
    solver->step();
    const std::uint64_t taken = solver->stage_times().substeps - before;
    if (step > 0 && taken != previous) ++changes;
    previous = taken;
    worst_density_error = std::max(worst_density_error, stats(*solver).max_density_error);
  }
  std::printf("resting pool, 8000: %d changes of the substep count, largest density error %.4f\n",
              changes, worst_density_error);
  EXPECT_LE(changes, 1);
  EXPECT_LT(worst_density_error, 0.015);
}

// It settles now: within 0.1 mm, 7 substeps every step (PbfSubsteps::kRecentSteps).
TEST(Pbf, ADeepPoolSettles) {
  const testing::DeepPoolWatch pool = testing::watch_deep_pool(testing::Backend::cpu);
  EXPECT_LT(pool.centre_of_mass_range, 0.002);
  EXPECT_LE(pool.substep_counts, 2u);
}

TEST(Pbf, SubstepsKeepFastFlowStable) {
  auto solver = make_solver(SolverKind::pbf, SceneKind::dam_break, 3000);
  run_for(*solver, 2.0);
  testing::expect_sound(*solver, 3000);
  EXPECT_LT(stats(*solver).max_density_error, 0.3);
}

// The CPU's rule hears of every step at once; a tolerance of 10 % lets as much compression build
// as the GPU's late figures did. The corrections' velocity cap (pbf_max_acceleration) holds it:
// 0.9 times the released energy, 4.3 times without the cap.
TEST(Pbf, CompressionLeftBehindDoesNotBurst) {
  const testing::DeepColumnEnergy e = testing::run_deep_thin_column(testing::Backend::cpu, 0.1f);
  EXPECT_LT(e.kinetic, 1.5 * e.released);
}

// A column at rest compresses at its foot before its average compression shows it: started at one
// substep a step, a 1M-particle dam break's column reached 71 % over rest density there by its
// fifth step (average 1.3 %) and sprang back with 1.6 times the energy its fall had released. The
// rule starts from the column's weight instead (PbfSubsteps::start). This thin column measured
// 14.2 % and 1.17 times from one substep, 8.3 % and 1.00 times from its weight.
TEST(Pbf, DeepColumnStartsFromItsWeight) {
  auto solver = make_solver(SolverKind::pbf, testing::deep_thin_column());
  const FluidStatistics start = stats(*solver);
  double worst_density_error = 0.0;
  for (int k = 0; k < 12; ++k) {
    solver->step();
    worst_density_error = std::max(worst_density_error, stats(*solver).max_density_error);
  }
  const FluidStatistics end = stats(*solver);
  const double released = static_cast<double>(end.particles) * solver->fluid().particle_mass *
                          glm::length(solver->gravity()) *
                          (start.centre_of_mass.y - end.centre_of_mass.y);
  std::printf(
      "deep thin column from rest: largest density error %.3f, kinetic energy %.3f J, "
      "released %.3f J\n",
      worst_density_error, end.kinetic_energy, released);
  EXPECT_LT(worst_density_error, 0.11);
  EXPECT_LT(end.kinetic_energy, 1.05 * released);
}

}  // namespace
}  // namespace fluidcast::sim

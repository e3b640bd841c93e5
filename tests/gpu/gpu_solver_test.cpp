// The GPU solvers on lavapipe (or the real device): they agree with the CPU solvers particle by
// particle over a dam break's first steps and on aggregate statistics after, a pool stays at rest,
// the stage timers count, and a count beyond the device's memory is refused up front. The extreme
// inputs are in unit/solver_inputs_test.cpp, on both backends.
#include "gpu/gpu_solver.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "../unit/solver_test_support.h"
#include "gpu_test_support.h"

namespace fluidcast::sim {
namespace {

using testing::Backend;
using testing::farthest_apart_by_id;
using testing::make_solver;
using testing::run_for;
using testing::stats;

class GpuSolverTest : public fluidcast::testing::GpuTest,
                      public ::testing::WithParamInterface<SolverKind> {};

// Both backends start from the same dam break and are compared at five times over 1 s. They
// cannot agree particle by particle: sums run in another order on the GPU (the order within a grid
// cell follows atomics) and the last bits differ, which a splashing flow amplifies. The aggregates
// stay close. Differences measured at 1000 particles on lavapipe (PBF / SPH, worst of the five
// times, six runs of this test, which prints them; densities with the walls' share): kinetic
// energy 1.4–3.7 % / 1.0–1.1 %, centre of mass 0.9–1.9 mm / 0.5–0.6 mm, front 0 / 0.2 mm, max
// density error 0.004–0.010 / 0.006–0.007, mean density error 0.0001–0.0002 / 0.00013. The
// tolerances are two to five times those, in units that mean something: a particle spacing for
// positions (4.6 cm here).
TEST_P(GpuSolverTest, AgreesWithTheCpuSolverOnADamBreak) {
  constexpr int kParticles = 1000;
  auto cpu = make_solver(GetParam(), SceneKind::dam_break, kParticles);
  auto gpu = make_solver(GetParam(), SceneKind::dam_break, kParticles, {}, Backend::gpu);
  const double spacing = cpu->fluid().spacing;
  for (const double until : {0.1, 0.25, 0.5, 0.75, 1.0}) {
    run_for(*cpu, until - cpu->time());
    // In lockstep: with steps in flight the GPU plans substeps from figures a few steps old, and
    // the trajectories would part by their plans, not by their arithmetic.
    while (gpu->time() < until - 0.5 * gpu->params().time_step) {
      gpu->step();
      gpu->synchronize();
    }
    SCOPED_TRACE("t = " + std::to_string(until) + " s");
    const FluidStatistics a = stats(*cpu), b = stats(*gpu);
    testing::expect_sound(*gpu, kParticles);
    EXPECT_NEAR(b.kinetic_energy, a.kinetic_energy, 0.1 * a.kinetic_energy + 0.5);
    EXPECT_LT(glm::length(b.centre_of_mass - a.centre_of_mass), 0.2 * spacing);
    EXPECT_NEAR(b.front_x, a.front_x, 0.5 * spacing);
    EXPECT_NEAR(b.max_density_error, a.max_density_error, 0.02);
    EXPECT_NEAR(b.avg_density_error, a.avg_density_error, 0.001);
    std::printf(
        "t %.2f s: kinetic energy %.3f / %.3f J, max density error %.4f / %.4f, mean density "
        "error %.5f / %.5f, front %.4f / %.4f m (CPU / GPU); centres of mass %.2f mm apart\n",
        until, a.kinetic_energy, b.kinetic_energy, a.max_density_error, b.max_density_error,
        a.avg_density_error, b.avg_density_error, a.front_x, b.front_x,
        1e3 * glm::length(b.centre_of_mass - a.centre_of_mass));
  }
}

// The density bound of the substep rule reads the compression the GPU adds up: with a tight
// tolerance a settling pool's steps are cut into more substeps, as the CPU solver cuts them.
// Measured on lavapipe: the same plan at each of the 20 steps (2, 2, then 1 five times, then 2);
// with the walls' share left out of the GPU's compression, 1 instead of 2 at 14 steps. A plan
// near a whole number may round either way: one step apart, and two over the run, are allowed.
TEST_P(GpuSolverTest, TheDensityBoundCutsStepsAsOnTheCpu) {
  if (GetParam() != SolverKind::pbf) GTEST_SKIP() << "a PBF rule";
  SolverParams params;
  params.pbf_density_tolerance = 0.001f;
  auto cpu = make_solver(SolverKind::pbf, SceneKind::pool, 1000, params);
  auto gpu = make_solver(SolverKind::pbf, SceneKind::pool, 1000, params, Backend::gpu);
  int most = 0, all_cpu = 0, all_gpu = 0;
  for (int k = 0; k < 20; ++k) {
    const int planned_cpu = cpu->substeps_for(params.time_step);
    const int planned_gpu = gpu->substeps_for(params.time_step);
    EXPECT_NEAR(planned_gpu, planned_cpu, 1) << "step " << k;
    most = std::max(most, planned_gpu);
    all_cpu += planned_cpu;
    all_gpu += planned_gpu;
    cpu->step(params.time_step, planned_cpu);
    gpu->step(params.time_step, planned_gpu);
    gpu->synchronize();
  }
  std::printf("substeps planned: %d (CPU) and %d (GPU), most in a step %d\n", all_cpu, all_gpu,
              most);
  EXPECT_NEAR(all_gpu, all_cpu, 2);
  EXPECT_GE(most, 2);
}

// SPH's substeps are planned from the largest speed and acceleration the GPU records, as the CPU
// plans them from its own (sph_stable_substep). A dam break at the defaults, where the speed of
// sound and the fluid's own speed set the plan, for 0.5 s; then one with a soft fluid (c = 5 m/s)
// under 200 m/s² of gravity, where the acceleration sets it, for its first ten steps (the CPU
// cuts each step as the state allows, the GPU into its plan's equal substeps, so the runs part,
// and a splashing flow soon parts their plans too). Measured on lavapipe: the same
// plan at every step of the first (344 substeps), within one of the second's (52 against 51);
// with the GPU's speed not recorded 300 against 344, with its acceleration not recorded 35
// against 51 (no test caught either before).
TEST_P(GpuSolverTest, TheSphBoundsPlanStepsAsOnTheCpu) {
  if (GetParam() != SolverKind::sph) GTEST_SKIP() << "SPH's bounds";
  const auto expect_plans_alike = [](const SolverParams& params, glm::vec3 gravity, int steps) {
    auto cpu = make_solver(SolverKind::sph, SceneKind::dam_break, 1000, params);
    auto gpu = make_solver(SolverKind::sph, SceneKind::dam_break, 1000, params, Backend::gpu);
    cpu->set_gravity(gravity);
    gpu->set_gravity(gravity);
    int all_cpu = 0, all_gpu = 0;
    for (int k = 0; k < steps; ++k) {
      const int planned_cpu = cpu->substeps_for(params.time_step);
      const int planned_gpu = gpu->substeps_for(params.time_step);
      EXPECT_NEAR(planned_gpu, planned_cpu, 1) << "step " << k;
      all_cpu += planned_cpu;
      all_gpu += planned_gpu;
      cpu->step(params.time_step, planned_cpu);
      gpu->step(params.time_step, planned_gpu);
      gpu->synchronize();
    }
    std::printf("substeps planned: %d (CPU) and %d (GPU)\n", all_cpu, all_gpu);
    EXPECT_NEAR(all_gpu, all_cpu, 2);
  };
  expect_plans_alike(SolverParams{}, kStandardGravity, 60);
  SolverParams soft;
  soft.sound_speed = 5.0f;
  expect_plans_alike(soft, {0.0f, -200.0f, 0.0f}, 10);
}

// As the CPU pool test (unit/pbf_test.cpp), at a size lavapipe runs in seconds: after 1 s of
// settling, density within 2 %, no drift beyond a tenth of a spacing, and only the slow slosh
// left from settling: rms speed below 0.15 m/s (measured here 0.051 m/s PBF, 0.099 m/s SPH). The
// kinetic energy at 1.5 s, `fluidcast-sim --scene pool --particles 1000 --iterations 10 --until
// 1.5 --backend cpu|gpu [--solver sph] --stats F`: PBF 0.078 J on the CPU, 0.15 J here; SPH 0.65
// and 0.69 J.
TEST_P(GpuSolverTest, PoolAtRestStaysAtRest) {
  SolverParams params;
  params.iterations = 10;
  auto solver = make_solver(GetParam(), SceneKind::pool, 1000, params, Backend::gpu);
  const testing::PoolAtRest pool = testing::watch_pool_at_rest(*solver, 1.0, 0.5);
  EXPECT_LT(pool.worst_density_error, 0.02);
  EXPECT_LT(pool.worst_drift, 0.1 * solver->fluid().spacing);
  EXPECT_LT(pool.final_rms_speed, 0.15);
}

TEST_P(GpuSolverTest, StageTimesComeFromTheGpu) {
  if (!context().timestamps_supported()) GTEST_SKIP() << "the device has no timestamps";
  SolverParams params;
  params.iterations = 3;
  auto solver = make_solver(GetParam(), SceneKind::dam_break, 500, params, Backend::gpu);
  run_for(*solver, 0.05);
  solver->synchronize();
  const StageTimes& t = solver->stage_times();
  EXPECT_GT(t.substeps, 0u);
  EXPECT_GT(t.grid_ms, 0.0);
  EXPECT_GT(t.neighbours_ms, 0.0);
  EXPECT_GT(t.predict_ms, 0.0);
  EXPECT_GT(t.solve_ms, 0.0);
  if (GetParam() == SolverKind::pbf) {
    ASSERT_EQ(t.iteration_ms.size(), 3u);
    EXPECT_NEAR(t.iteration_ms[0] + t.iteration_ms[1] + t.iteration_ms[2], t.solve_ms, 1e-6);
    EXPECT_GT(t.velocity_ms, 0.0);
    EXPECT_GT(t.viscosity_ms, 0.0);
  }
}

TEST_P(GpuSolverTest, MoreParticlesThanTheMemoryBudgetAreRefusedUpFront) {
  SceneParams scene;
  scene.kind = SceneKind::pool;
  scene.particles = 1000;
  // What 999 particles need: one more does not fit.
  const std::uint64_t budget =
      gpu_solver::GpuSolver(GetParam(), context(), build_scene(scene), {}).bytes_needed(999);
  try {
    gpu_solver::GpuSolver(GetParam(), context(), build_scene(scene), {}, nullptr, budget);
    ADD_FAILURE() << "no error";
  } catch (const ParamError& e) {
    std::printf("%s\n", e.what());
    EXPECT_NE(std::string(e.what()).find("1000 particles need"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("999 particles would fit"), std::string::npos) << e.what();
  }
  // The device's own memory takes the default budget, and holds the thousand.
  EXPECT_GE(
      gpu_solver::GpuSolver(GetParam(), context(), build_scene(scene), {}).particles_that_fit(),
      1000u);
}

// However much memory there is, the neighbour lists' 32-bit index bounds the count: at kernel
// ratio 4 a particle lists up to 537 neighbours, 135 elements of four entries, and 2^31 elements
// hold 15,907,286 particles' lists.
TEST_P(GpuSolverTest, TheNeighbourListsIndexBoundsTheParticlesThatFit) {
  SceneParams scene;
  scene.kind = SceneKind::pool;
  scene.particles = 1000;
  SolverParams params;
  params.kernel_ratio = 4.0f;
  const std::uint64_t terabyte = std::uint64_t{1} << 40;
  const gpu_solver::GpuSolver solver(GetParam(), context(), build_scene(scene), params, nullptr,
                                     terabyte);
  ASSERT_EQ(solver.fluid().max_neighbours, 537u);
  EXPECT_EQ(solver.particles_listable(), 15907286u);
  // A particle's lists take 135 × 16 bytes, and they are one buffer.
  const std::uint64_t in_one_allocation = context().info().largest_allocation_bytes / 2160;
  EXPECT_EQ(solver.particles_listed_in_one_allocation(), in_one_allocation);
  EXPECT_EQ(solver.particles_that_fit(), std::min<std::uint64_t>(15907286u, in_one_allocation));
}

// Lists larger than the device allocates in one piece (lavapipe: 2 GiB, 994,205 particles at
// ratio 4) are refused up front with that limit named, not by the allocator's out-of-memory.
TEST_P(GpuSolverTest, ListsLargerThanOneAllocationAreRefusedUpFront) {
  SolverParams params;
  params.kernel_ratio = 4.0f;
  SceneParams scene;
  scene.kind = SceneKind::pool;
  scene.particles = 1000;
  const std::uint64_t terabyte = std::uint64_t{1} << 40;
  const gpu_solver::GpuSolver small(GetParam(), context(), build_scene(scene), params, nullptr,
                                    terabyte);
  const std::size_t most = small.particles_listed_in_one_allocation();
  if (most >= small.particles_listable()) {
    GTEST_SKIP() << "this device allocates the lists up to their index bound";
  }
  scene.particles = static_cast<int>(most + 1);
  params.max_particles = scene.particles;
  try {
    gpu_solver::GpuSolver(GetParam(), context(), build_scene(scene), params, nullptr, terabyte);
    ADD_FAILURE() << "no error";
  } catch (const ParamError& e) {
    std::printf("%s\n", e.what());
    const std::string text = e.what();
    EXPECT_NE(text.find("particles: " + std::to_string(most + 1) + " particles"),
              std::string::npos);
    EXPECT_NE(text.find("in one piece"), std::string::npos);
    EXPECT_NE(text.find("at most " + std::to_string(most) + " particles at this ratio"),
              std::string::npos);
  }
}

// fluidcast-bench-gpu --pipeline-statistics: every pass listed, with what the driver says of its
// code where the device offers it (NVIDIA's drivers: registers and the like), and nothing but a
// sentence in the log where it does not (lavapipe). Its own context, the validation layer on.
TEST(GpuSolverPipelineStatistics, EveryPassIsListedWithWhatTheDriverSays) {
  gpu::ContextOptions options = gpu::options_from_environment();
  options.validation = true;
  options.pipeline_statistics = true;
  std::vector<std::string> log;
  options.log = [&](const std::string& line) { log.push_back(line); };
  gpu::Context context(options);
  const std::vector<PassStatistics> passes = gpu_solver_pipeline_statistics(context);
  ASSERT_EQ(passes.size(), 13u);
  EXPECT_EQ(passes[1].pass, "grid_scan");
  EXPECT_EQ(passes[6].pass, "neighbours");
  for (const PassStatistics& pass : passes) {
    EXPECT_EQ(pass.statistics.empty(), !context.pipeline_statistics_captured()) << pass.pass;
    for (const auto& [name, value] : pass.statistics) {
      EXPECT_FALSE(name.empty() || value.empty()) << pass.pass;
    }
  }
  const bool said_so = std::any_of(log.begin(), log.end(), [](const std::string& line) {
    return line.find("does not offer VK_KHR_pipeline_executable_properties") != std::string::npos;
  });
  EXPECT_EQ(said_so, !context.pipeline_statistics_captured());
  EXPECT_TRUE(context.validation_errors().empty());
}

// As Pbf.CompressionLeftBehindDoesNotBurst (unit/pbf_test.cpp), on the GPU with the default
// tolerance and its steps in flight, as the server runs it: 1.05 times the released energy since
// the rule starts from the column's weight (1.36 from one substep; 1.19 after 20 steps, as the
// CPU solver), 3.0 times (14 m/s) while the rule trusted figures four steps old and the
// corrections' velocity was not capped; with the cap alone 0.97 here, but 1.65 after 20 steps.
// Tighter than the CPU test's bound, so that the start from one substep fails here.
class GpuPbfTest : public fluidcast::testing::GpuTest {};

TEST_F(GpuPbfTest, CompressionLeftBehindDoesNotBurst) {
  const testing::DeepColumnEnergy e =
      testing::run_deep_thin_column(Backend::gpu, SolverParams{}.pbf_density_tolerance);
  EXPECT_LT(e.kinetic, 1.25 * e.released);
}

// As Pbf.ADeepPoolSettles (unit/pbf_test.cpp), with the GPU's steps in flight: the rule's
// allowance for steps unseen must not switch on and off in a fluid at rest near its bound.
TEST_F(GpuPbfTest, ADeepPoolSettles) {
  const testing::DeepPoolWatch pool = testing::watch_deep_pool(Backend::gpu);
  EXPECT_LT(pool.centre_of_mass_range, 0.002);
  EXPECT_LE(pool.substep_counts, 2u);
}

// The iterations' weights reach the correction pass: six steps of a dam break, in lockstep, give
// the CPU's kinetic energy damped and in full (measured with fluidcast-sim: the damping moves
// the energy by 0.8 %, the backends differ by 3·10⁻⁷ of the energy).
TEST_F(GpuPbfTest, JacobiDampingWeighsTheIterationsAsOnTheCpu) {
  const auto kinetic_energy = [](Backend backend, float damping) {
    SolverParams params;
    params.pbf_jacobi_damping = damping;
    auto solver = make_solver(SolverKind::pbf, SceneKind::dam_break, 1000, params, backend);
    for (int step = 0; step < 6; ++step) {
      solver->step();
      solver->synchronize();
    }
    return stats(*solver).kinetic_energy;
  };
  const double cpu_damped = kinetic_energy(Backend::cpu, 0.5f);
  const double cpu_in_full = kinetic_energy(Backend::cpu, 0.0f);
  const double by_the_damping = std::abs(cpu_damped - cpu_in_full);
  ASSERT_GT(by_the_damping, 1e-3 * cpu_in_full);
  EXPECT_NEAR(kinetic_energy(Backend::gpu, 0.5f), cpu_damped, 0.05 * by_the_damping);
  EXPECT_NEAR(kinetic_energy(Backend::gpu, 0.0f), cpu_in_full, 0.05 * by_the_damping);
}

// PBF's plan from the solver's fluid as it is now, with `unseen` steps to come before the planned
// one, each of which may add gravity's Δt to a speed: its travel and wall bounds, as
// GpuSolver::substeps_for reads them. A fresh rule, with no density bound: the tests below keep
// theirs out of the plan (a fluid nothing compresses, a loose tolerance). The snapshot submits
// the steps waiting in the solver's batch.
int plan_from_now(const gpu_solver::GpuSolver& solver, int unseen) {
  const ParticleSet now = solver.snapshot();
  float fastest = 0.0f;
  for (const glm::vec3& v : now.velocity) fastest = std::max(fastest, glm::length(v));
  const float step = solver.params().time_step, g = glm::length(solver.gravity());
  const float gained = static_cast<float>(unseen) * g * step;
  const float approach =
      largest_wall_approach(now.position, now.velocity, solver.inner_tank(), solver.wall_reach());
  const PbfSubsteps rule(solver.params(), solver.fluid().kernel_radius);
  return rule.count(step, fastest + gained, 0.0f, approach > 0.0f ? approach + gained : 0.0f, g,
                    unseen);
}

// A loose density tolerance: what the density bound plans stays below the bounds a test watches.
SolverParams density_bound_out_of_the_plan() {
  SolverParams params;
  params.pbf_density_tolerance = 0.1f;
  return params;
}

// PBF's substep rule counts a particle closing on a wall as far ahead as the figures that plan a
// step may be old (wall_reach: the steps in flight, and the step itself), which the last pass of
// each substep measures. The column, without gravity, is thrown at 6 m/s at either end wall from
// so far that after one step its front would be three quarters of that reach from the wall: the
// next plan takes the walls' bound, more than the travel bound. Measured on lavapipe: the fastest
// approach 6.65 m/s, the nearest particle 0.66 of the reach away, and 2 substeps planned; 1 with
// the shader's reach halved on either side (the other wall tests' fluid comes within half of it,
// and did not see that).
TEST_F(GpuPbfTest, CountsAFluidClosingOnAWallFromAsFarAsItsFiguresMayBeOld) {
  const SolverParams params = density_bound_out_of_the_plan();
  const float step = params.time_step;
  constexpr float kSpeed = 6.0f;
  SceneParams scene;
  scene.kind = SceneKind::dam_break;
  scene.particles = 1000;
  for (const float toward : {-1.0f, 1.0f}) {
    SCOPED_TRACE(toward < 0.0f ? "toward the near wall" : "toward the far wall");
    gpu_solver::GpuSolver gpu(SolverKind::pbf, context(), build_scene(scene), params);
    gpu.set_gravity({0.0f, 0.0f, 0.0f});
    const float reach = gpu.wall_reach();
    std::vector<glm::vec3> positions = gpu.snapshot().position;
    float front = -toward * std::numeric_limits<float>::infinity();  // the end nearest the wall
    for (const glm::vec3& p : positions) front = toward * std::max(toward * front, toward * p.x);
    const float wall = toward < 0.0f ? gpu.inner_tank().min.x : gpu.inner_tank().max.x;
    const float gap = 0.75f * kSpeed * reach + kSpeed * step;
    for (glm::vec3& p : positions) p.x += wall - toward * gap - front;
    gpu.replace_particles(positions,
                          std::vector<glm::vec3>(positions.size(), {toward * kSpeed, 0.0f, 0.0f}));
    gpu.step();
    gpu.synchronize();
    const ParticleSet after = gpu.snapshot();
    float fastest = 0.0f, soonest = std::numeric_limits<float>::infinity();  // s to the wall
    for (std::size_t i = 0; i < after.size(); ++i) {
      fastest = std::max(fastest, glm::length(after.velocity[i]));
      const float closing = toward * after.velocity[i].x;
      if (closing > 0.0f)
        soonest = std::min(soonest, toward * (wall - after.position[i].x) / closing);
    }
    ASSERT_LT(soonest, reach) << "the column is out of the reach after a step";
    ASSERT_GT(soonest, 0.5f * reach) << "the column came within half the reach in a step";
    const int planned = gpu.substeps_for(step);
    std::printf("nearest particle %.2f of the reach away: %d substeps planned\n", soonest / reach,
                planned);
    EXPECT_EQ(planned, plan_from_now(gpu, 0));
    EXPECT_GT(planned, PbfSubsteps(params, gpu.fluid().kernel_radius)
                           .count(step, fastest, 0.0f, 0.0f, 0.0f));  // the travel bound's
  }
}

// A ball of water, 20 cm across, loaded at rest without gravity in the dam break's tank, away from
// every wall (so that only the travel bound plans until it nears the far wall, and the density
// rule starts with no bound: nothing compresses the ball), then pulled along the tank toward the
// far wall at 1000 m/s², 8.3 m/s faster each step (up to the speed limit of the substeps its
// steps take). Its steps wait in `batch`, so that those not yet submitted are certain not to have
// finished.
std::unique_ptr<gpu_solver::GpuSolver> pulled_ball(gpu::Context& context, GpuStepBatch& batch) {
  SceneParams scene;
  scene.kind = SceneKind::dam_break;
  scene.particles = 1000;
  auto solver = std::make_unique<gpu_solver::GpuSolver>(
      SolverKind::pbf, context, build_scene(scene), density_bound_out_of_the_plan(), &batch);
  solver->set_gravity({0.0f, 0.0f, 0.0f});
  const std::vector<glm::vec3> ball =
      ball_of_particles({0.3f, 0.5f, 0.15f}, 0.1f, solver->fluid().spacing, solver->tank());
  solver->replace_particles(ball, std::vector<glm::vec3>(ball.size(), glm::vec3(0.0f)));
  solver->set_gravity({1000.0f, 0.0f, 0.0f});
  return solver;
}

// The travel and wall bounds count the steps that have not finished: each may add g·Δt to the
// speeds the plan reads. Twice, with two steps waiting: first with one step seen (8.3 m/s, far
// from the walls), where the plan is the travel bound's for 25 m/s; then with those two seen too
// (22 m/s, the speed limit of their two substeps; within the far wall's reach), where it is the
// walls' bound's for an approach of 39 m/s. Measured on lavapipe: 4 and 12 substeps, against 2
// and 8 for the figures seen alone; with the speed's allowance left out 2 at first, with the
// approach's 8 then (no test caught either before).
TEST_F(GpuPbfTest, StepsNotYetFinishedCountForTheTravelAndWallBounds) {
  GpuStepBatch batch(context());
  const auto ball = pulled_ball(context(), batch);
  const float step = ball->params().time_step;
  ball->step(step, 1);
  for (const char* bound : {"travel", "walls"}) {
    SCOPED_TRACE(bound);
    batch.submit();
    ball->synchronize();
    const int seen = ball->substeps_for(step);
    const int expected = plan_from_now(*ball, 2);
    ASSERT_GT(expected, plan_from_now(*ball, 0));
    ball->step(step, seen);
    ball->step(step, seen);
    const int planned = ball->substeps_for(step);
    std::printf("pulled ball, %s: %d substeps seen, %d planned with two steps waiting\n", bound,
                seen, planned);
    EXPECT_EQ(planned, expected);
  }
}

// Steps that finish together are counted in their order: the plan reads the newest one's
// figures. Three steps of the pulled ball, finished together: the plan is the rule's for the
// fluid at the third step's end, 25 m/s and within the far wall's reach. Measured on lavapipe:
// 9 substeps; with the finished steps read newest first (the oldest's figures kept), 2 (no test
// caught that before).
TEST_F(GpuPbfTest, StepsFinishedTogetherLeaveTheNewestFigures) {
  GpuStepBatch batch(context());
  const auto ball = pulled_ball(context(), batch);
  const float step = ball->params().time_step;
  for (const int substeps : {1, 2, 3}) ball->step(step, substeps);
  batch.submit();
  ball->synchronize();
  const int planned = ball->substeps_for(step);
  std::printf("pulled ball, three steps finished together: %d substeps planned\n", planned);
  EXPECT_EQ(planned, plan_from_now(*ball, 0));
}

// A fluid just loaded plans its first step from its own speed and walls, which the GPU has not
// measured yet: the pulled ball without gravity, loaded at 20 m/s toward the far wall (out of its
// reach: the travel bound plans) and at 40 m/s (within it: the walls' bound). Measured on
// lavapipe: 2 and 10 substeps; with the loaded speed left out 1 and 10, with the loaded approach
// left out 2 and 4 (no test caught either before).
TEST_F(GpuPbfTest, AFluidJustLoadedPlansFromItsOwnSpeedAndWalls) {
  GpuStepBatch batch(context());
  const auto ball = pulled_ball(context(), batch);
  ball->set_gravity({0.0f, 0.0f, 0.0f});
  const ParticleSet at_rest = ball->snapshot();
  for (const float speed : {20.0f, 40.0f}) {
    SCOPED_TRACE(std::to_string(speed) + " m/s");
    ball->replace_particles(at_rest.position,
                            std::vector<glm::vec3>(at_rest.size(), {speed, 0.0f, 0.0f}));
    const int planned = ball->substeps_for(ball->params().time_step);
    std::printf("ball loaded at %.0f m/s: %d substeps planned\n", speed, planned);
    EXPECT_EQ(planned, plan_from_now(*ball, 0));
  }
}

// A fluid loaded while steps run plans from itself: those steps' figures describe the fluid it
// replaced. The pulled ball after two steps finished but not yet read back, replaced by itself at
// rest without gravity: one substep, as for any fluid at rest. Measured on lavapipe: 1; with the
// replaced fluid's figures counted, 2 (no test caught that before).
TEST_F(GpuPbfTest, AFluidLoadedWhileStepsRunPlansFromItself) {
  GpuStepBatch batch(context());
  const auto ball = pulled_ball(context(), batch);
  const float step = ball->params().time_step;
  const ParticleSet at_rest = ball->snapshot();
  ball->step(step, 1);
  ball->step(step, 2);
  ASSERT_GT(plan_from_now(*ball, 0), 1);  // the fluid those steps leave
  ball->set_gravity({0.0f, 0.0f, 0.0f});
  ball->replace_particles(at_rest.position, at_rest.velocity);
  ball->synchronize();
  EXPECT_EQ(ball->substeps_for(step), 1);
}

// A finger pushed through the middle of `fluid` at 3 m/s, for both solvers: where it stands within
// a step, and what it does to the particles it meets, show in lockstep.
void push_a_finger_through(const ParticleSet& fluid, Solver& a, Solver& b) {
  glm::vec3 middle(0.0f);
  for (const glm::vec3& p : fluid.position) middle += p;
  const Collider finger{middle / static_cast<float>(fluid.size()), 0.08f, {3.0f, 0.0f, 0.0f}};
  a.set_colliders({&finger, 1});
  b.set_colliders({&finger, 1});
}

// `steps` steps of `seconds` each, in `substeps` equal substeps, on both solvers, the count the
// CPU took checked at every step (CPU SPH sets its substeps from the state), and each GPU step
// finished before the next, so that PBF's density bound has heard of the same steps on both (it
// sets how stiff the corrections are: PbfSubsteps::stiffness_substep) and the runs part only by
// the order of their sums. Call it in ASSERT_NO_FATAL_FAILURE.
void step_in_lockstep(Solver& cpu, Solver& gpu, float seconds, int substeps, int steps) {
  for (int step = 0; step < steps; ++step) {
    ASSERT_EQ(cpu.step(seconds, substeps), substeps) << "step " << step;
    gpu.step(seconds, substeps);
    gpu.synchronize();
  }
}

// Each pass of a GPU substep, particle by particle: six steps of two substeps of a dam break from
// rest in lockstep with the CPU solver, at every pass structure (PBF with one iteration, where the
// listing's λ and the correction that sets the velocity are the whole solve, two, and four; PBF
// without vorticity confinement, whose sums pass computes no ω and whose finish pass confines
// nothing, and without XSPH either; PBF with strong confinement and no XSPH, where the confinement
// over the whole step shows: confining over the last substep's length alone parted the run by 1.4
// mm against 2 µm; PBF with strong XSPH alone, where the GPU's c uncompounded parted it by 3.1 mm
// (the structures at the default c by 0.7–1.3 mm); SPH), then every particle's position against the
// CPU's. The sums pass runs only on a step's last substep; on the others the last correction pass
// writes the state back, with no finish pass. Sums in another order leave the last bits apart (the
// order within a grid cell follows atomics); six steps from rest hardly amplify them. Measured on
// lavapipe (1000 particles, spacing 4.6 cm, the fastest moved 6–7 cm): PBF 0.7–1.4 µm apart;
// SPH 1.5 mm, as the GPU's substeps are equal within a step and the CPU's adapt. With one neighbour
// left out of the listing's sums the run parted by 7.7–22 mm (PBF) and 39 mm (SPH) (at the solvers'
// own substeps), and with the finish pass taking the sums pass's velocity where that pass had not
// run, by 37 mm (measured when only PBF without vorticity or XSPH skipped the sums pass; every PBF
// structure skips it now). Bounds: a hundredth of a spacing for PBF, a fifth for SPH.
struct PassStructure {
  SolverKind kind;
  int iterations;
  float vorticity = SolverParams{}.vorticity;
  float xsph_viscosity = SolverParams{}.xsph_viscosity;
};
class GpuStepsTest : public fluidcast::testing::GpuTest,
                     public ::testing::WithParamInterface<PassStructure> {};

TEST_P(GpuStepsTest, MoveEveryParticleAsTheCpuSolverDoes) {
  const PassStructure structure = GetParam();
  SolverParams params;
  params.iterations = structure.iterations;
  params.vorticity = structure.vorticity;
  params.xsph_viscosity = structure.xsph_viscosity;
  auto cpu = make_solver(structure.kind, SceneKind::dam_break, 1000, params);
  auto gpu = make_solver(structure.kind, SceneKind::dam_break, 1000, params, Backend::gpu);
  // Two substeps a step, so that each step has one that is not its last (where the sums pass may
  // not run). Not step_in_lockstep: the CPU's SPH takes as many as the state asks.
  for (int step = 0; step < 6; ++step) {
    cpu->step(params.time_step, 2);
    gpu->step(params.time_step, 2);
    gpu->synchronize();
  }
  const double farthest_apart = farthest_apart_by_id(cpu->snapshot(), gpu->snapshot());
  const double spacing = cpu->fluid().spacing;
  const bool pbf = structure.kind == SolverKind::pbf;
  std::printf("%s, %d iterations, vorticity %g, XSPH %g: farthest apart %.3g m\n",
              pbf ? "PBF" : "SPH", structure.iterations, structure.vorticity,
              structure.xsph_viscosity, farthest_apart);
  EXPECT_LT(farthest_apart, (pbf ? 0.01 : 0.2) * spacing);
}

// PBF where its limits act, in lockstep (two substeps a step, as the CPU solver is told): the dam
// break's column squeezed to 0.85 of its size toward the tank's corner (1.6 times rest density,
// so that the corrections' velocity is capped at pbf_max_acceleration·Δt), every tenth particle
// thrown at 400 m/s along x (so that the prediction slows it to pbf_travel·h a substep), and a
// finger pushed through. Two steps, then every particle against the CPU's. Measured on lavapipe
// (1000 particles, spacing 4.6 cm): 5.4 µm apart (30 µm before PBF kept its density bound's
// stiffness and step_in_lockstep waited for each GPU step); with the cap
// doubled 96 mm, without the prediction's speed limit 1.24 m, with the finger where it stands a
// substep into the step on every substep 46 mm (no test caught these three before). Bound: a
// hundredth of a spacing, as GpuStepsTest's.
TEST_F(GpuPbfTest, MovesASqueezedThrownFluidAsTheCpuSolverDoesInLockstep) {
  const SolverParams params;
  auto cpu = make_solver(SolverKind::pbf, SceneKind::dam_break, 1000, params);
  auto gpu = make_solver(SolverKind::pbf, SceneKind::dam_break, 1000, params, Backend::gpu);
  const ParticleSet lattice = cpu->snapshot();
  glm::vec3 corner(std::numeric_limits<float>::infinity());
  for (const glm::vec3& p : lattice.position) corner = glm::min(corner, p);
  ParticleSet start;
  for (std::size_t i = 0; i < lattice.size(); ++i) {
    const glm::vec3 thrown = i % 10 == 0 ? glm::vec3(400.0f, 0.0f, 0.0f) : glm::vec3(0.0f);
    start.append(corner + 0.85f * (lattice.position[i] - corner), thrown,
                 static_cast<std::uint32_t>(i));
  }
  cpu->replace_particles(start.position, start.velocity);
  gpu->replace_particles(start.position, start.velocity);
  push_a_finger_through(start, *cpu, *gpu);
  ASSERT_NO_FATAL_FAILURE(step_in_lockstep(*cpu, *gpu, params.time_step, 2, 2));
  const ParticleSet cpu_end = cpu->snapshot();
  const double farthest_apart = farthest_apart_by_id(cpu_end, gpu->snapshot());
  std::printf(
      "PBF squeezed and thrown, in lockstep: farthest apart %.3g m, farthest moved %.3g m\n",
      farthest_apart, farthest_apart_by_id(start, cpu_end));
  EXPECT_LT(farthest_apart, 0.01 * cpu->fluid().spacing);
}

// SPH in lockstep: steps short enough that the CPU solver, which sets each substep's length from
// the state just computed, takes two substeps a step as the GPU does (the count checked at every
// step; they are the step's halves, as the GPU's, where the state allows half a step, which the
// agreement below shows it did), so that the runs part only by the order of their sums. The fluid
// starts sheared, 2 m/s from the floor to the column's top, with μ = 5 Pa·s: the viscous term moves
// it, and at the surface a particle's density and its neighbours' differ, so that the term's
// weights show. Measured on lavapipe (1000 particles, 20 steps of 2 ms, the fastest moved 8.1 cm):
// 0.24 µm apart; 117 µm with the viscous term weighted by the particle's own density instead of
// each neighbour's, which GpuStepsTest's SPH case, parted 1.5 mm by its adaptive substeps, does not
// see. Bound: a thousandth of a spacing (46 µm).
class GpuSphTest : public fluidcast::testing::GpuTest {};

TEST_F(GpuSphTest, MovesEveryParticleAsTheCpuSolverDoesInLockstep) {
  SolverParams params;
  params.sph_viscosity = 5.0f;
  auto cpu = make_solver(SolverKind::sph, SceneKind::dam_break, 1000, params);
  auto gpu = make_solver(SolverKind::sph, SceneKind::dam_break, 1000, params, Backend::gpu);
  const ParticleSet lattice = cpu->snapshot();
  float height = 0.0f;
  for (const glm::vec3& p : lattice.position) height = std::max(height, p.y);
  ParticleSet start;
  for (std::size_t i = 0; i < lattice.size(); ++i) {
    const glm::vec3 p = lattice.position[i];
    start.append(p, {2.0f * p.y / height, 0.0f, 0.0f}, static_cast<std::uint32_t>(i));
  }
  cpu->replace_particles(start.position, start.velocity);
  gpu->replace_particles(start.position, start.velocity);
  ASSERT_NO_FATAL_FAILURE(step_in_lockstep(*cpu, *gpu, 2.0e-3f, 2, 20));
  const ParticleSet cpu_end = cpu->snapshot();
  const double farthest_apart = farthest_apart_by_id(cpu_end, gpu->snapshot());
  const double farthest_moved = farthest_apart_by_id(start, cpu_end);
  std::printf("SPH in lockstep: farthest apart %.3g m, farthest moved %.3g m\n", farthest_apart,
              farthest_moved);
  EXPECT_LT(farthest_apart, 0.001 * cpu->fluid().spacing);
}

// SPH with a finger pushed through the dam break's column, in lockstep: steps of 0.5 ms, one
// substep each (the finger's pushes shorten the CPU's substeps below 1 ms now and then, so two a
// step would not stay equal), so that the walls' and the finger's hold on the velocity show.
// Measured on lavapipe (20 steps, the farthest pushed 8.0 cm): 0.12 µm apart; with the finger
// taking away half of a particle's speed toward it instead of all, 2.0 mm (no test caught that
// before). Bound: a thousandth of a spacing, as the sheared fluid's.
TEST_F(GpuSphTest, PushesAFingerThroughTheFluidAsTheCpuSolverDoesInLockstep) {
  const SolverParams params;
  auto cpu = make_solver(SolverKind::sph, SceneKind::dam_break, 1000, params);
  auto gpu = make_solver(SolverKind::sph, SceneKind::dam_break, 1000, params, Backend::gpu);
  const ParticleSet start = cpu->snapshot();
  push_a_finger_through(start, *cpu, *gpu);
  ASSERT_NO_FATAL_FAILURE(step_in_lockstep(*cpu, *gpu, 0.5e-3f, 1, 20));
  const ParticleSet cpu_end = cpu->snapshot();
  const double farthest_apart = farthest_apart_by_id(cpu_end, gpu->snapshot());
  std::printf("SPH with a finger, in lockstep: farthest apart %.3g m, farthest moved %.3g m\n",
              farthest_apart, farthest_apart_by_id(start, cpu_end));
  EXPECT_LT(farthest_apart, 0.001 * cpu->fluid().spacing);
}

INSTANTIATE_TEST_SUITE_P(EveryPassStructure, GpuStepsTest,
                         ::testing::Values(PassStructure{SolverKind::pbf, 1},
                                           PassStructure{SolverKind::pbf, 2},
                                           PassStructure{SolverKind::pbf, 4},
                                           PassStructure{SolverKind::pbf, 4, 0.0f},
                                           PassStructure{SolverKind::pbf, 4, 0.0f, 0.0f},
                                           PassStructure{SolverKind::pbf, 2, 1.0f, 0.0f},
                                           PassStructure{SolverKind::pbf, 2, 0.0f, 0.5f},
                                           PassStructure{SolverKind::sph, 1}));

INSTANTIATE_TEST_SUITE_P(BothSolvers, GpuSolverTest,
                         ::testing::Values(SolverKind::pbf, SolverKind::sph), testing::solver_name);

}  // namespace
}  // namespace fluidcast::sim

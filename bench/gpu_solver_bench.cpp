// GPU solver throughput on the dam break: steps/s (wall clock, the GPU kept busy with two steps in
// flight) and GPU milliseconds per stage per step from timestamps: grid build (counting sort and
// reorder; PBF's count is in predict), the neighbour lists (with PBF's first λ, SPH's densities),
// predict, each density iteration (the last sets the velocity), vorticity (the curl, XSPH and the
// compression, on a step's last substep), viscosity (the confinement and the state written back,
// on a step's last substep; the others write theirs back in their last iteration), and the whole
// per substep. Sizes are the talk's table (27k–216k) and beyond, up to
// 2M; 2, 4 (the default) and 6 iterations; a fixed dt of 1 ms, as the talk steps, with CFL
// substeps where the flow needs them (the `substeps` column). At 216k and 1M also a session's own
// step (1/120 s, `dt_us:8333`) over the dam break's first half second, where the substep rule cuts
// each step into many: GPU seconds a simulated second (`gpu_s_per_simulated_s`), which a frame
// loop's solver share must pay for the fluid to run in real time.
// `Sessions/...`: many small fluids stepped one substep each per round, their steps in one
// submission (`batched`, as the server records a tick) or each in its own (`serial`): GPU
// milliseconds per round for all of them together, and the wall clock per round.
// `--smoke` runs small cases (for CI, on lavapipe); `--device N` picks the device;
// `--pipeline-statistics` prints first what the driver says of each pass's compiled code
// (registers and the like; where the device offers VK_KHR_pipeline_executable_properties);
// other flags go to Google Benchmark (e.g. --benchmark_filter=Pbf).
#include <benchmark/benchmark.h>

#include <chrono>
#include <cstdio>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "bench_main.h"
#include "fluidcast/gpu/context.h"
#include "fluidcast/sim/gpu_solver_statistics.h"
#include "fluidcast/sim/gpu_step_batch.h"
#include "fluidcast/sim/solver.h"

namespace {

using namespace fluidcast;
using namespace fluidcast::sim;

// Steps timed per benchmark iteration, after `kWarmUpSteps` untimed ones from t = 0.
constexpr int kWarmUpSteps = 5;

// state.range: particles, iterations, the step in µs.
void run_dam_break(benchmark::State& state, SolverKind kind, int steps_per_iteration) {
  SceneParams scene;
  scene.particles = static_cast<int>(state.range(0));
  SolverParams params;
  params.iterations = static_cast<int>(state.range(1));
  params.time_step = static_cast<float>(state.range(2)) * 1e-6f;
  params.max_particles = std::max(params.max_particles, scene.particles);
  auto solver = make_gpu_solver(kind, bench::gpu_context(), build_scene(scene), params);
  for (int k = 0; k < kWarmUpSteps; ++k) solver->step();
  solver->synchronize();
  solver->clear_stage_times();

  double seconds = 0.0;
  for (auto _ : state) {
    const auto start = std::chrono::steady_clock::now();
    for (int k = 0; k < steps_per_iteration; ++k) solver->step();
    solver->synchronize();
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    state.SetIterationTime(elapsed);
    seconds += elapsed;
  }

  const StageTimes& t = solver->stage_times();
  const double steps = static_cast<double>(state.iterations()) * steps_per_iteration;
  state.counters["steps_per_s"] = steps / seconds;
  state.counters["substeps"] = static_cast<double>(t.substeps) / steps;
  state.counters["grid_ms"] = t.grid_ms / steps;
  state.counters["neighbours_ms"] = t.neighbours_ms / steps;
  state.counters["predict_ms"] = t.predict_ms / steps;
  state.counters["solve_ms"] = t.solve_ms / steps;
  for (std::size_t k = 0; k < t.iteration_ms.size(); ++k) {
    state.counters["iteration" + std::to_string(k + 1) + "_ms"] = t.iteration_ms[k] / steps;
  }
  state.counters["velocity_ms"] = t.velocity_ms / steps;
  state.counters["viscosity_ms"] = t.viscosity_ms / steps;
  state.counters["gpu_ms"] = t.total_ms() / steps;
  state.counters["gpu_ms_per_substep"] =
      t.substeps > 0 ? t.total_ms() / static_cast<double>(t.substeps) : 0.0;
  state.counters["gpu_s_per_simulated_s"] =
      1e-3 * t.total_ms() / (steps * static_cast<double>(params.time_step));
}

// state.range: sessions, particles each, batched (1) or serial (0).
void run_sessions(benchmark::State& state, int rounds_per_iteration) {
  const auto sessions = static_cast<std::size_t>(state.range(0));
  const bool batched = state.range(2) != 0;
  SceneParams scene;
  scene.particles = static_cast<int>(state.range(1));
  SolverParams params;
  params.iterations = 4;
  params.time_step = 1e-3f;
  GpuStepBatch batch(bench::gpu_context());
  std::vector<std::unique_ptr<Solver>> solvers;
  for (std::size_t k = 0; k < sessions; ++k) {
    solvers.push_back(make_gpu_solver(SolverKind::pbf, bench::gpu_context(), build_scene(scene),
                                      params, batched ? &batch : nullptr));
  }
  const auto round = [&] {
    for (auto& solver : solvers) solver->step(params.time_step, 1);
    batch.submit();  // nothing waits there when serial
  };
  for (int k = 0; k < kWarmUpSteps; ++k) round();
  for (auto& solver : solvers) {
    solver->synchronize();
    solver->clear_stage_times();
  }

  double seconds = 0.0;
  for (auto _ : state) {
    const auto start = std::chrono::steady_clock::now();
    for (int k = 0; k < rounds_per_iteration; ++k) round();
    for (auto& solver : solvers) solver->synchronize();
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    state.SetIterationTime(elapsed);
    seconds += elapsed;
  }
  const double rounds = static_cast<double>(state.iterations()) * rounds_per_iteration;
  double total_ms = 0.0;
  for (auto& solver : solvers) total_ms += solver->stage_times().total_ms();
  state.counters["gpu_ms"] = total_ms / rounds;
  state.counters["wall_ms"] = 1e3 * seconds / rounds;
}

void add_sessions(bool batched, int sessions, int particles, int rounds) {
  benchmark::RegisterBenchmark(batched ? "Sessions/batched" : "Sessions/serial", run_sessions,
                               rounds)
      ->Args({sessions, particles, batched ? 1 : 0})
      ->ArgNames({"sessions", "particles", "batched"})
      ->Iterations(1)
      ->UseManualTime()
      ->Unit(benchmark::kMillisecond);
}

// The talk's step, 1 ms, and a session's, 1/120 s.
constexpr int kTalkStepUs = 1000;
constexpr int kSessionStepUs = 8333;

void add(const char* name, SolverKind kind, int particles, int iterations, int steps,
         int step_us = kTalkStepUs) {
  benchmark::RegisterBenchmark(name, run_dam_break, kind, steps)
      ->Args({particles, iterations, step_us})
      ->ArgNames({"particles", "iterations", "dt_us"})
      ->Iterations(1)
      ->UseManualTime()
      ->Unit(benchmark::kMillisecond);
}

void print_pipeline_statistics() {
  for (const PassStatistics& pass : gpu_solver_pipeline_statistics(bench::gpu_context())) {
    std::printf("pipeline %s:", pass.pass.c_str());
    for (const auto& [name, value] : pass.statistics) {
      std::printf(" %s %s;", name.c_str(), value.c_str());
    }
    std::printf("\n");
  }
  std::fflush(stdout);
}

void register_cases(bool smoke) {
  if (bench::gpu_context().pipeline_statistics_captured()) print_pipeline_statistics();
  if (smoke) {
    add("Pbf/dam_break", SolverKind::pbf, 4000, 2, 3);
    add("Pbf/dam_break", SolverKind::pbf, 4000, 4, 3, kSessionStepUs);
    add("Sph/dam_break", SolverKind::sph, 4000, 1, 1);
    for (bool batched : {false, true}) add_sessions(batched, 4, 2000, 3);
    return;
  }
  for (int iterations : {2, 4, 6}) {
    for (int particles : {27000, 64000, 125000, 216000, 500000, 1000000, 2000000}) {
      add("Pbf/dam_break", SolverKind::pbf, particles, iterations, 200);
    }
  }
  // Its first half second after the warm-up, 60 steps.
  for (int particles : {216000, 1000000}) {
    add("Pbf/dam_break", SolverKind::pbf, particles, 4, 60, kSessionStepUs);
  }
  for (int particles : {27000, 216000, 1000000}) {
    add("Sph/dam_break", SolverKind::sph, particles, 1, 20);
  }
  for (const auto& [sessions, particles] :
       {std::pair{32, 64000}, std::pair{32, 8000}, std::pair{8, 64000}}) {
    for (bool batched : {false, true}) add_sessions(batched, sessions, particles, 100);
  }
}

}  // namespace

int main(int argc, char** argv) { return bench::run_gpu_benchmarks(argc, argv, register_cases); }

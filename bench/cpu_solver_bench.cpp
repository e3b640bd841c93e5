// CPU solver throughput on the dam break: steps/s and wall ms per stage, per step, from t = 0
// (scene set-up excluded). `--smoke` runs one tiny case, for CI. Other flags go to Google
// Benchmark (e.g. --benchmark_filter=Pbf).
#include <benchmark/benchmark.h>

#include <string>

#include "bench_main.h"
#include "fluidcast/sim/solver.h"

namespace {

using namespace fluidcast::sim;

void run_dam_break(benchmark::State& state, SolverKind kind) {
  SceneParams scene;
  scene.particles = static_cast<int>(state.range(0));
  SolverParams params;
  params.iterations = static_cast<int>(state.range(1));
  params.time_step = static_cast<float>(state.range(3)) * 1e-6f;
  params.threads = static_cast<int>(state.range(2));
  auto solver = make_cpu_solver(kind, build_scene(scene), params);
  for (auto _ : state) solver->step();

  const StageTimes& t = solver->stage_times();
  using benchmark::Counter;
  const double steps = static_cast<double>(state.iterations());
  state.counters["steps_per_s"] = Counter(steps, Counter::kIsRate);
  state.counters["grid_ms"] = t.grid_ms / steps;
  state.counters["neighbours_ms"] = t.neighbours_ms / steps;
  state.counters["predict_ms"] = t.predict_ms / steps;
  state.counters["solve_ms"] = t.solve_ms / steps;
  state.counters["velocity_ms"] = t.velocity_ms / steps;
  state.counters["substeps"] = static_cast<double>(t.substeps) / steps;
}

void register_cases(bool smoke) {
  if (smoke) {
    benchmark::RegisterBenchmark("Pbf/dam_break", run_dam_break, SolverKind::pbf)
        ->Args({1000, 2, 2, 8333})
        ->Iterations(5)
        ->UseRealTime()
        ->Unit(benchmark::kMillisecond);
    benchmark::RegisterBenchmark("Sph/dam_break", run_dam_break, SolverKind::sph)
        ->Args({1000, 1, 2, 8333})
        ->Iterations(2)
        ->UseRealTime()
        ->Unit(benchmark::kMillisecond);
    return;
  }
  // The table: 5k, 10k, 27k, 64k particles; 2 and 6 iterations; 2 threads; 0.5 s of the
  // collapse from t = 0. dt = 1 ms is a fixed step that never needs a CFL substep (one solver
  // step per step, as a fixed-dt library takes); dt = 1/120 s is our default, where the CFL
  // bound splits fast steps into substeps (the `substeps` column).
  for (int dt_us : {1000, 8333}) {
    for (int iterations : {2, 6}) {
      for (int particles : {5000, 10000, 27000, 64000}) {
        benchmark::RegisterBenchmark("Pbf/dam_break", run_dam_break, SolverKind::pbf)
            ->Args({particles, iterations, 2, dt_us})
            ->ArgNames({"particles", "iterations", "threads", "dt_us"})
            ->Iterations(500000 / dt_us)
            ->UseRealTime()
            ->Unit(benchmark::kMillisecond);
      }
    }
  }
  for (int particles : {5000, 27000}) {
    benchmark::RegisterBenchmark("Sph/dam_break", run_dam_break, SolverKind::sph)
        ->Args({particles, 1, 2, 8333})
        ->ArgNames({"particles", "iterations", "threads", "dt_us"})
        ->Iterations(30)
        ->UseRealTime()
        ->Unit(benchmark::kMillisecond);
  }
}

}  // namespace

int main(int argc, char** argv) {
  return fluidcast::bench::run_benchmarks(argc, argv, [](const fluidcast::bench::BenchOptions& o) {
    register_cases(o.smoke);
    return 0;
  });
}

#include "session/default_size.h"

#include <algorithm>
#include <chrono>
#include <limits>

#include "fluidcast/sim/scene.h"
#include "fluidcast/sim/solver.h"

namespace fluidcast::server {

DefaultSize choose_default_particles(const std::function<double(std::uint32_t)>& ms_per_substep,
                                     std::uint32_t most, double steps_per_second, double share) {
  const double substeps_per_second = steps_per_second * kSubstepsPerStepInMotion;
  DefaultSize chosen;
  for (const std::uint32_t rung : kDefaultParticleLadder) {
    const std::uint32_t particles = std::min(rung, most);
    const double ms = ms_per_substep(particles);
    const double device_share = ms * substeps_per_second / 1000.0;
    if (chosen.particles != 0 && device_share > share) break;
    chosen = {particles, ms, device_share};
    if (particles == most) break;
  }
  return chosen;
}

double measure_ms_per_substep(gpu::Context& context, bool gpu_solver, std::uint32_t particles) {
  sim::SceneParams scene;
  scene.kind = sim::SceneKind::dam_break;
  scene.particles = static_cast<int>(particles);
  sim::SolverParams params;
  params.max_particles = static_cast<int>(particles);
  auto solver =
      gpu_solver
          ? sim::make_gpu_solver(sim::SolverKind::pbf, context, sim::build_scene(scene), params)
          : sim::make_cpu_solver(sim::SolverKind::pbf, sim::build_scene(scene), params);
  constexpr int kWarmUp = 2;  // first use: pipelines, caches, pages
  for (int i = 0; i < kWarmUp; ++i) solver->step();
  solver->synchronize();
  // The least of a few short rounds: another process's burst on a shared machine only lengthens
  // a round, so the least is the solver's own cost.
  constexpr int kRounds = 3;
  constexpr int kStepsPerRound = 2;
  double least = std::numeric_limits<double>::infinity();
  for (int round = 0; round < kRounds; ++round) {
    solver->clear_stage_times();
    int substeps = 0;
    const auto begun = std::chrono::steady_clock::now();
    for (int i = 0; i < kStepsPerRound; ++i) {
      substeps += solver->step(params.time_step, solver->substeps_for(params.time_step));
    }
    solver->synchronize();
    const double wall_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - begun).count();
    const sim::StageTimes& times = solver->stage_times();
    const double gpu_ms = times.total_ms();
    least = std::min(least, gpu_solver && times.substeps > 0
                                ? gpu_ms / static_cast<double>(times.substeps)
                                : wall_ms / substeps);
  }
  return least;
}

}  // namespace fluidcast::server

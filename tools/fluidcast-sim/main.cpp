// fluidcast-sim: runs a scene headless on the CPU or GPU solver; prints the geometry, optionally
// progress, writes statistics CSV, PLY dumps and rendered frames. Bad flags: one line on stderr,
// exit code 2.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <optional>

#include "fluidcast/gpu/context.h"
#include "fluidcast/sim/statistics.h"
#include "frames.h"
#include "options.h"
#include "outputs.h"

namespace {

using namespace fluidcast;
using Clock = std::chrono::steady_clock;

void print_geometry(const tools::SimOptions& o, const sim::Solver& solver) {
  const sim::ParticleSet p = solver.snapshot();
  sim::Box water{p.position.empty() ? glm::vec3(0) : p.position[0], glm::vec3(0)};
  water.max = water.min;
  for (const glm::vec3& x : p.position) {
    water.min = glm::min(water.min, x);
    water.max = glm::max(water.max, x);
  }
  const float half = solver.fluid().particle_radius();
  const glm::vec3 tank = solver.tank().size();
  const glm::vec3 extent = water.size() + glm::vec3(2 * half);
  const auto& f = solver.fluid();
  std::printf("scene %s, solver %s, %zu particles\n",
              std::string(sim::to_string(o.scene.kind)).c_str(),
              std::string(sim::to_string(o.solver_kind)).c_str(), p.size());
  std::printf("tank %.3f x %.3f x %.3f m (length x height x depth)\n", tank.x, tank.y, tank.z);
  std::printf("water at start spans %.3f x %.3f x %.3f m\n", extent.x, extent.y, extent.z);
  std::printf("particle spacing %.4f m, kernel radius %.4f m, mass %.4g kg\n", f.spacing,
              f.kernel_radius, f.particle_mass);
  std::printf("time step %.5f s, %lld steps (%.3f s simulated)", o.solver.time_step,
              static_cast<long long>(o.steps), o.steps * double(o.solver.time_step));
  if (o.solver_kind == sim::SolverKind::pbf) std::printf(", %d iterations", o.solver.iterations);
  std::printf("\n");
  std::fflush(stdout);
}

// For --backend auto: a GPU that is hardware (or one asked for by index) runs the GPU solver.
bool hardware_gpu_present(const tools::SimOptions& o) {
  if (o.device || std::getenv("FLUIDCAST_DEVICE")) return true;
  try {
    for (const auto& device : gpu::list_devices()) {
      if (device.rejected_because.empty() && device.hardware()) return true;
    }
  } catch (const gpu::GpuUnavailable&) {
  }
  return false;
}

std::unique_ptr<gpu::Context> open_context(const tools::SimOptions& o) {
  gpu::ContextOptions options = gpu::options_from_environment();
  if (o.device) options.device_index = o.device;
  return std::make_unique<gpu::Context>(options);
}

// What a run writes as it goes: statistics (CSV), particles (PLY) and frames, each as often as
// asked.
struct Recorder {
  const tools::SimOptions& o;
  std::optional<tools::StatsCsv> csv;
  std::optional<tools::FrameWriter> frames;

  // After a step of `substeps` substeps (0: before the first).
  void operator()(sim::Solver& solver, int substeps) {
    if (csv) {
      csv->write(solver.steps(), solver.time(),
                 sim::measure(solver.snapshot(), solver.fluid(), solver.tank()), substeps);
    }
    if (o.dump_every > 0 && solver.steps() % static_cast<std::uint64_t>(o.dump_every) == 0) {
      char name[32];
      std::snprintf(name, sizeof(name), "step_%08llu.ply",
                    static_cast<unsigned long long>(solver.steps()));
      tools::write_ply(std::filesystem::path(o.dump_dir) / name, solver.snapshot());
    }
    if (frames && solver.steps() % static_cast<std::uint64_t>(o.render_every) == 0) {
      frames->write(solver);
    }
  }
};

struct Stepping {
  double seconds = 0;  // spent stepping alone
  std::uint64_t substeps = 0;
  int most_substeps = 0;  // in one step
};

// Steps --steps times, recording each and saying progress once a second.
Stepping step_all(const tools::SimOptions& o, sim::Solver& solver, Recorder& record) {
  auto last_report = Clock::now();
  std::uint64_t steps_at_report = 0;
  Stepping stepping;
  for (std::int64_t k = 0; k < o.steps; ++k) {
    const auto before = Clock::now();
    const float seconds = solver.params().time_step;
    const int substeps = solver.step(seconds, solver.substeps_for(seconds));
    stepping.seconds += std::chrono::duration<double>(Clock::now() - before).count();
    stepping.substeps += static_cast<std::uint64_t>(substeps);
    stepping.most_substeps = std::max(stepping.most_substeps, substeps);
    record(solver, substeps);
    const auto now = Clock::now();
    if (o.progress && now - last_report >= std::chrono::seconds(1)) {
      const double wall = std::chrono::duration<double>(now - last_report).count();
      std::printf("step %llu  t = %.3f s  %.1f steps/s\n",
                  static_cast<unsigned long long>(solver.steps()), solver.time(),
                  double(solver.steps() - steps_at_report) / wall);
      std::fflush(stdout);
      last_report = now;
      steps_at_report = solver.steps();
    }
  }
  const auto before_sync = Clock::now();
  solver.synchronize();  // a GPU solver may still be running the last steps
  stepping.seconds += std::chrono::duration<double>(Clock::now() - before_sync).count();
  return stepping;
}

int run(const tools::SimOptions& o) {
  std::unique_ptr<gpu::Context> context;  // outlives the solver
  std::unique_ptr<sim::Solver> solver;
  const bool on_gpu = o.backend == tools::Backend::gpu ||
                      (o.backend == tools::Backend::automatic && hardware_gpu_present(o));
  if (o.backend == tools::Backend::automatic) {
    std::printf("backend auto: %s\n", on_gpu ? "gpu" : "cpu (no hardware Vulkan device)");
  }
  if (on_gpu) {
    context = open_context(o);
    solver = sim::make_gpu_solver(o.solver_kind, *context, sim::build_scene(o.scene), o.solver);
  } else {
    solver = sim::make_cpu_solver(o.solver_kind, sim::build_scene(o.scene), o.solver);
  }
  print_geometry(o, *solver);

  Recorder record{o, std::nullopt, std::nullopt};
  if (!o.render_dir.empty() || !o.video_path.empty()) {
    if (!context) context = open_context(o);  // the CPU solver's particles drawn on the GPU
    record.frames.emplace(o, *context, *solver);
  }
  if (!o.stats_path.empty()) record.csv.emplace(o.stats_path);
  if (o.dump_every > 0) std::filesystem::create_directories(o.dump_dir);
  record(*solver, 0);
  const auto start = Clock::now();
  const Stepping stepping = step_all(o, *solver, record);
  if (record.frames) record.frames->finish();
  const double wall = std::chrono::duration<double>(Clock::now() - start).count();
  const auto stats = sim::measure(solver->snapshot(), solver->fluid(), solver->tank());
  std::printf(
      "done: %llu steps, t = %.3f s simulated in %.2f s wall; stepping alone %.1f steps/s; "
      "%llu substeps (at most %d a step); front_x %.3f m, centre of mass %.3f m high, largest "
      "speed %.2f m/s, max density error %.4f, spray %.3f %%\n",
      static_cast<unsigned long long>(solver->steps()), solver->time(), wall,
      double(o.steps) / stepping.seconds, static_cast<unsigned long long>(stepping.substeps),
      stepping.most_substeps, stats.front_x, stats.centre_of_mass.y, stats.max_speed,
      stats.max_density_error, 100.0 * stats.spray_share);
  return stats.non_finite == 0 && stats.outside_tank == 0 ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  const auto parsed = fluidcast::tools::parse_sim_options(argc, argv);
  if (!parsed.options) return parsed.exit_code;
  try {
    return run(*parsed.options);
  } catch (const fluidcast::sim::ParamError& e) {
    std::cerr << "fluidcast-sim: " << e.what() << '\n';
    return 2;
  } catch (const fluidcast::gpu::GpuUnavailable& e) {
    std::cerr << "fluidcast-sim: " << e.what() << '\n';
    return 2;

  } catch (const std::exception& e) {
    std::cerr << "fluidcast-sim: " << e.what() << '\n';
    return 1;
  }
}

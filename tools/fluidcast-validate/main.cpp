// fluidcast-validate: the solvers against experiment. Two cases:
// - dam break: a column of base a = 2.25 in and height 2a (Martin & Moyce's n² = 2) collapses in
//   a tank 7a long; the surge front (statistics.h, surge_front) against their Table 2 for
//   T ≤ 4.44, with the simulated clock shifted as theirs were (T = 1.19 at Z = 1.44);
// - resting pool: the default pool settles for 1 s, then its density error is watched for 2 s.
// Writes CSV and SVG charts into --out, prints a summary, and exits 1 when a figure misses its
// bound (the bounds default to the project's targets; --fast runs small, for the test suite,
// with bounds that tell working from broken). Bad flags: one line on stderr, exit code 2.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>

#include "fluidcast/command_line.h"
#include "fluidcast/gpu/context.h"
#include "fluidcast/sim/solver.h"
#include "fluidcast/sim/statistics.h"
#include "martin_moyce.h"
#include "spec_options.h"
#include "svg_plot.h"

namespace {

using namespace fluidcast;
using validation::FrontPoint;

constexpr double kColumnWidth = 2.25 * 0.0254;  // m: Martin & Moyce's a

struct Options {
  std::string out = "validation";
  std::string backend = "cpu";
  sim::SolverKind solver = sim::SolverKind::pbf;
  int column_resolution = 40;  // a over the particle spacing
  int pool_particles = 10000;
  sim::SolverParams params;
  double max_front_error = 0.10;
  double max_average_density_error = 0.005;
  double max_density_error = 0.02;
};

std::unique_ptr<sim::Solver> make(const Options& o, const sim::SceneParams& scene,
                                  gpu::Context* context) {
  if (context) return sim::make_gpu_solver(o.solver, *context, sim::build_scene(scene), o.params);
  return sim::make_cpu_solver(o.solver, sim::build_scene(scene), o.params);
}

void write(const std::filesystem::path& path, const std::string& text) {
  std::ofstream(path) << text;
}

struct Verdict {
  bool passed = true;
  void check(bool ok, const char* what, double value, double bound) {
    std::printf("  %-40s %8.4f (bound %.4f) %s\n", what, value, bound, ok ? "ok" : "MISSED");
    passed = passed && ok;
  }
};

// A column a wide and 2a high in a tank 7a long (Martin & Moyce's n² = 2), thin in depth.
sim::SceneParams dam_break_scene(const Options& o) {
  const double a = kColumnWidth;
  const double spacing = a / o.column_resolution;
  sim::SceneParams scene;
  scene.kind = sim::SceneKind::dam_break;
  scene.column_width = static_cast<float>(a);
  scene.column_height = static_cast<float>(2 * a);
  scene.tank_length = static_cast<float>(7 * a);
  scene.tank_height = static_cast<float>(3 * a);
  // Thin, so that the flow is plane between free-slip walls; at least the scenes' smallest depth.
  double smallest_depth = 0.0;
  for (const auto& spec : sim::scene_param_specs()) {
    if (spec.name == "depth") smallest_depth = spec.min;
  }
  const double depth = std::max(8 * spacing, smallest_depth);
  scene.depth = static_cast<float>(depth);
  scene.particles =
      static_cast<int>(std::lround(2 * a * a * depth / (spacing * spacing * spacing)));
  return scene;
}

// The experiment's front, the simulated one, and the simulated one shifted as their runs were.
std::string front_chart(std::span<const FrontPoint> experiment,
                        const std::vector<FrontPoint>& simulated, double shift,
                        std::size_t particles) {
  const double last_T = experiment.back().T;
  validation::Chart chart;
  chart.title = "Dam break, n² = 2: surge front against Martin & Moyce (1952), " +
                std::to_string(particles) + " particles";
  chart.x_label = "T = t·√(2g/a)";
  chart.y_label = "Z = x / a";
  validation::Series experiment_series{"experiment", "black", true, {}, {}};
  for (const FrontPoint& e : experiment) {
    experiment_series.x.push_back(e.T);
    experiment_series.y.push_back(e.Z);
  }
  validation::Series raw_series{"simulated", "#1f77b4", false, {}, {}};
  validation::Series shifted_series{"simulated, shifted", "#d62728", false, {}, {}};
  for (const FrontPoint& p : simulated) {
    if (p.T > last_T + 0.3) break;
    raw_series.x.push_back(p.T);
    raw_series.y.push_back(p.Z);
    shifted_series.x.push_back(p.T + shift);
    shifted_series.y.push_back(p.Z);
  }
  chart.series = {experiment_series, raw_series, shifted_series};
  return validation::to_svg(chart);
}

void dam_break(const Options& o, gpu::Context* context, Verdict& verdict) {
  const double a = kColumnWidth;
  auto solver = make(o, dam_break_scene(o), context);
  const double gravity = glm::length(solver->gravity());
  const double n = std::sqrt(2.0);
  const auto experiment = validation::martin_moyce_n2_front();
  const double last_T = experiment.back().T;
  const double t_end = last_T / (n * std::sqrt(gravity / a)) + 0.05;

  std::vector<FrontPoint> simulated;
  std::string csv = "t_s,front_m,T,Z\n";
  while (true) {
    const sim::ParticleSet particles = solver->snapshot();
    const double front = sim::surge_front(particles, solver->fluid().spacing, solver->tank());
    const FrontPoint p = validation::to_martin_moyce(solver->time(), front, a, gravity, n);
    simulated.push_back(p);
    csv += std::to_string(solver->time()) + "," + std::to_string(front) + "," +
           std::to_string(p.T) + "," + std::to_string(p.Z) + "\n";
    if (solver->time() >= t_end) break;
    solver->step();
  }
  write(std::filesystem::path(o.out) / "dam_break_front.csv", csv);

  const double shift = validation::shift_as_martin_and_moyce(simulated);
  const auto raw = validation::compare_fronts(simulated, experiment, 0.0, last_T);
  const auto shifted = validation::compare_fronts(simulated, experiment, shift, last_T);

  write(std::filesystem::path(o.out) / "dam_break_front.svg",
        front_chart(experiment, simulated, shift, solver->particle_count()));

  std::printf("dam break: a = %.5f m, %zu particles (a/d = %d), %s %s, %llu steps\n", a,
              solver->particle_count(), o.column_resolution, o.backend.c_str(),
              std::string(sim::to_string(o.solver)).c_str(),
              static_cast<unsigned long long>(solver->steps()));
  std::printf(
      "  front error over T ≤ %.2f, as simulated: mean %.1f %%, worst %.1f %% (%zu points)\n",
      last_T, 100 * raw.mean_relative_error, 100 * raw.worst_relative_error, raw.points);
  std::printf(
      "  shifted by ΔT = %+.3f as their runs were: mean %.1f %%, worst %.1f %% (%zu points)\n",
      shift, 100 * shifted.mean_relative_error, 100 * shifted.worst_relative_error, shifted.points);
  verdict.check(shifted.points >= 10, "points compared (at least 10)", double(shifted.points), 10);
  verdict.check(shifted.mean_relative_error <= o.max_front_error,
                "front: mean |Z error| / Z, shifted", shifted.mean_relative_error,
                o.max_front_error);
}

void resting_pool(const Options& o, gpu::Context* context, Verdict& verdict) {
  sim::SceneParams scene;
  scene.kind = sim::SceneKind::pool;
  scene.particles = o.pool_particles;
  auto solver = make(o, scene, context);
  constexpr double kSettle = 1.0, kWatch = 2.0, kEvery = 0.05;
  std::string csv = "t_s,avg_density_error,max_density_error\n";
  validation::Series average{"average", "#1f77b4", false, {}, {}};
  validation::Series largest{"largest", "#d62728", false, {}, {}};
  double average_sum = 0.0, worst = 0.0;
  int watched = 0;
  const int steps_per_sample =
      std::max(1, static_cast<int>(std::lround(kEvery / solver->params().time_step)));
  while (solver->time() < kSettle + kWatch - 1e-9) {
    for (int k = 0; k < steps_per_sample; ++k) solver->step();
    const sim::FluidStatistics s =
        sim::measure(solver->snapshot(), solver->fluid(), solver->tank());
    csv += std::to_string(solver->time()) + "," + std::to_string(s.avg_density_error) + "," +
           std::to_string(s.max_density_error) + "\n";
    average.x.push_back(solver->time());
    average.y.push_back(100 * s.avg_density_error);
    largest.x.push_back(solver->time());
    largest.y.push_back(100 * s.max_density_error);
    if (solver->time() > kSettle) {
      average_sum += s.avg_density_error;
      worst = std::max(worst, s.max_density_error);
      ++watched;
    }
  }
  write(std::filesystem::path(o.out) / "pool_density.csv", csv);
  validation::Chart chart;
  chart.title = "Resting pool, " + std::to_string(solver->particle_count()) +
                " particles: density error max(ρ/ρ0 − 1, 0)";
  chart.x_label = "t (s); settling until 1 s";
  chart.y_label = "density error (%)";
  chart.series = {average, largest};
  write(std::filesystem::path(o.out) / "pool_density.svg", validation::to_svg(chart));

  const double mean_average = watched > 0 ? average_sum / watched : 0.0;
  std::printf("resting pool: %zu particles, %s %s, %.0f s watched after %.0f s settling\n",
              solver->particle_count(), o.backend.c_str(),
              std::string(sim::to_string(o.solver)).c_str(), kWatch, kSettle);
  verdict.check(mean_average <= o.max_average_density_error, "pool: average density error",
                mean_average, o.max_average_density_error);
  verdict.check(worst <= o.max_density_error, "pool: largest density error", worst,
                o.max_density_error);
}

// Both runs against their bounds; charts and data in --out. The process's exit status.
int validate(const Options& o) {
  Verdict verdict;
  try {
    std::filesystem::create_directories(o.out);
    std::unique_ptr<gpu::Context> context;
    if (o.backend == "gpu") context = std::make_unique<gpu::Context>();
    dam_break(o, context.get(), verdict);
    resting_pool(o, context.get(), verdict);
  } catch (const sim::ParamError& e) {
    std::fprintf(stderr, "fluidcast-validate: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fluidcast-validate: %s\n", e.what());
    return 3;
  }
  std::printf("%s; charts and data in %s/\n", verdict.passed ? "all within bounds" : "MISSED",
              o.out.c_str());
  return verdict.passed ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  CLI::App app{
      "fluidcast-validate: the solvers against Martin & Moyce's dam break (1952) and a "
      "resting pool's density error"};
  add_version_flag(app, "fluidcast-validate");
  bool fast = false;
  std::string solver_name = "pbf";
  app.add_flag("--fast", fast,
               "Small runs for the test suite (a/d = 12, 2000 pool particles); with bounds that "
               "tell working from broken unless given");
  app.add_option("--out", o.out, "Folder for the CSV files and SVG charts")->capture_default_str();
  app.add_option("--backend", o.backend, "cpu or gpu (Vulkan compute on the best device)")
      ->check(CLI::IsMember({"cpu", "gpu"}))
      ->capture_default_str();
  app.add_option("--solver", solver_name, "pbf or sph")->capture_default_str();
  auto* resolution = app.add_option("--column-resolution", o.column_resolution,
                                    "Dam break: column width over particle spacing, 4 to 400")
                         ->check(CLI::Range(4, 400))
                         ->capture_default_str();
  auto* pool = app.add_option("--pool-particles", o.pool_particles,
                              "Resting pool: particles, 100 to 10000000")
                   ->check(CLI::Range(100, 10000000))
                   ->capture_default_str();
  tools::add_spec_options(app, o.params, sim::solver_param_specs());
  auto* front = app.add_option("--max-front-error", o.max_front_error,
                               "Bound on the mean relative front error (shifted)")
                    ->check(finite_range(0.0, 10.0))
                    ->capture_default_str();
  auto* average = app.add_option("--max-average-density-error", o.max_average_density_error,
                                 "Bound on the pool's average density error")
                      ->check(finite_range(0.0, 1.0))
                      ->capture_default_str();
  auto* largest = app.add_option("--max-density-error", o.max_density_error,
                                 "Bound on the pool's largest density error")
                      ->check(finite_range(0.0, 1.0))
                      ->capture_default_str();
  try {
    app.parse(argc, argv);
    o.solver = sim::parse_solver(solver_name);
    sim::validate(o.params);
  } catch (const CLI::ParseError& e) {
    return exit_for(app, e);
  } catch (const sim::ParamError& e) {
    std::fprintf(stderr, "fluidcast-validate: %s\n", e.what());
    return 2;
  }
  if (fast) {
    if (resolution->count() == 0) o.column_resolution = 12;
    if (pool->count() == 0) o.pool_particles = 2000;
    if (front->count() == 0) o.max_front_error = 0.25;
    if (average->count() == 0) o.max_average_density_error = 0.01;
    if (largest->count() == 0) o.max_density_error = 0.05;
  }
  o.params.max_particles = std::max(
      {o.params.max_particles, o.pool_particles, 32 * o.column_resolution * o.column_resolution});
  return validate(o);
}

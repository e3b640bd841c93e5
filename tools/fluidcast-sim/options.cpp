#include "options.h"

#include <CLI/CLI.hpp>
#include <cmath>
#include <iostream>

namespace fluidcast::tools {
namespace {

constexpr int kBadInput = 2;

// One CLI option per spec, bound to the struct field it describes.
template <class Owner>
void add_spec_options(CLI::App& app, Owner& owner, const std::vector<sim::ParamSpec<Owner>>& specs) {
  for (const auto& spec : specs) {
    const std::string flag = "--" + std::string(spec.name);
    const std::string help = std::string(spec.description) + " [" + std::string(spec.unit) +
                             ", range " + sim::format_range(spec.min, spec.max) + "]";
    std::visit([&](auto member) { app.add_option(flag, owner.*member, help)->capture_default_str(); },
               spec.member);
  }
}

std::string tuning_markdown() {
  return "## Scene\n\n" + sim::describe_markdown(sim::SceneParams{}, sim::scene_param_specs()) +
         "\n## Solvers\n\n" + sim::describe_markdown(sim::SolverParams{}, sim::solver_param_specs());
}

}  // namespace

ParseOutcome parse_sim_options(int argc, char** argv) {
  SimOptions o;
  CLI::App app{"fluidcast-sim: run a fluid scene headless, write statistics and particle dumps"};
  std::string scene_name = "dam_break", solver_name = "pbf";
  std::optional<std::int64_t> steps;
  std::optional<double> until;
  bool list_params = false;
  app.add_option("--scene", scene_name, "dam_break, double_dam_break, drop or pool")
      ->capture_default_str();
  app.add_option("--solver", solver_name, "pbf or sph")->capture_default_str();
  auto* steps_opt = app.add_option("--steps", steps, "Number of steps to run");
  auto* until_opt = app.add_option("--until", until, "Simulated seconds to run");
  steps_opt->excludes(until_opt);
  app.add_option("--stats", o.stats_path, "Write per-step statistics as CSV to this file");
  app.add_option("--dump-every", o.dump_every, "Write particle positions as PLY every M steps");
  app.add_option("--dump-dir", o.dump_dir, "Folder for PLY dumps")->capture_default_str();
  app.add_flag("--progress", o.progress, "Print progress once a second");
  app.add_flag("--list-params", list_params, "Print every tunable as a Markdown table and exit");
  add_spec_options(app, o.scene, sim::scene_param_specs());
  add_spec_options(app, o.solver, sim::solver_param_specs());

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return {std::nullopt, app.exit(e)};
  } catch (const CLI::ParseError& e) {
    std::cerr << "fluidcast-sim: " << e.what() << '\n';
    return {std::nullopt, kBadInput};
  }
  if (list_params) {
    std::cout << tuning_markdown();
    return {std::nullopt, 0};
  }

  try {
    o.scene.kind = sim::parse_scene(scene_name);
    o.solver_kind = sim::parse_solver(solver_name);
    sim::validate(o.scene);
    sim::validate(o.solver);
    if (!steps && !until) throw sim::ParamError("--steps or --until: one of them is required");
    if (steps) {
      if (*steps < 1 || *steps > 100'000'000)
        throw sim::ParamError("--steps: value " + std::to_string(*steps) +
                              " is out of range; accepted range [1, 100000000]");
      o.steps = *steps;
    } else {
      if (!std::isfinite(*until) || *until <= 0 || *until > 1e6)
        throw sim::ParamError("--until: value " + std::to_string(*until) +
                              " is out of range; accepted range (0, 1e6] s");
      const double step_count = std::ceil(*until / o.solver.time_step - 1e-6);
      if (step_count < 1 || step_count > 100'000'000)
        throw sim::ParamError("--until: " + std::to_string(*until) + " s is " +
                              std::to_string(step_count) + " steps of --time-step; accepted " +
                              "range [1, 100000000] steps");
      o.steps = static_cast<std::int64_t>(step_count);
    }
    if (o.dump_every < 0)
      throw sim::ParamError("--dump-every: value " + std::to_string(o.dump_every) +
                            " is negative; 0 means no dumps");
  } catch (const sim::ParamError& e) {
    std::cerr << "fluidcast-sim: " << e.what() << '\n';
    return {std::nullopt, kBadInput};
  }
  return {o, 0};
}

}  // namespace fluidcast::tools

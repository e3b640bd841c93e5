// fluidcast-sim's command line: every scene and solver tunable comes from its ParamSpec table.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>

#include "fluidcast/render/frame_renderer.h"
#include "fluidcast/sim/scene.h"
#include "fluidcast/sim/solver.h"

namespace fluidcast::tools {

// auto: the GPU solver on a hardware Vulkan device, else the CPU solver (faster than the GPU
// solver on lavapipe, Mesa's CPU implementation of Vulkan).
enum class Backend { cpu, gpu, automatic };

struct SimOptions {
  sim::SceneParams scene;
  sim::SolverParams solver;
  sim::SolverKind solver_kind = sim::SolverKind::pbf;
  Backend backend = Backend::cpu;
  std::optional<std::uint32_t> device;  // --device; else FLUIDCAST_DEVICE, else the best
  std::int64_t steps = 0;               // resolved from --steps or --until
  std::string stats_path;
  std::int64_t dump_every = 0;
  std::string dump_dir = "dumps";
  // --render: one PNG per rendered frame into render_dir, every render_every steps.
  std::string render_dir;
  std::string video_path;  // --video: the rendered frames through ffmpeg into this file
  std::int64_t render_every = 2;
  std::string renderer = "auto";
  bool narrow_range_filter = true;  // --ssfr-filter narrow (else bilateral)
  float ssfr_depth_falloff = render::SsfrStyle{}.depth_falloff_radii;  // --ssfr-depth-range
  bool ssfr_anisotropic = render::SsfrStyle{}.anisotropic;             // --ssfr-particles
  int ssfr_spray_neighbours = render::SsfrStyle{}.spray_neighbours;    // --ssfr-spray-below
  bool colour_by_density = false;  // --colour-by density (points)
  int width = 640, height = 360;
  std::optional<std::array<float, 3>> camera;  // yaw, pitch (degrees), distance (m)
  bool progress = false;
};

// What parsing decided: run with options, or exit with a code (help printed, or a bad flag
// reported on stderr in one line).
struct ParseOutcome {
  std::optional<SimOptions> options;
  int exit_code = 0;
};

ParseOutcome parse_sim_options(int argc, char** argv);

}  // namespace fluidcast::tools

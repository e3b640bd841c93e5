// What fluidcast-sim writes: per-step statistics as CSV, particle positions as PLY.
#pragma once

#include <cstdint>
#include <filesystem>
#include <fstream>

#include "fluidcast/sim/particles.h"
#include "fluidcast/sim/statistics.h"

namespace fluidcast::tools {

class StatsCsv {
 public:
  explicit StatsCsv(const std::filesystem::path& path);  // throws std::runtime_error
  // `substeps`: those the step took (0 on the row before the first step).
  void write(std::uint64_t step, double time, const sim::FluidStatistics& s, int substeps);

 private:
  std::ofstream out_;
};

// Binary little-endian PLY with x, y, z and the velocity vx, vy, vz per vertex.
void write_ply(const std::filesystem::path& path, const sim::ParticleSet& particles);

}  // namespace fluidcast::tools

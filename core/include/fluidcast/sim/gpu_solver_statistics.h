// What the driver says of the GPU solvers' compiled passes (registers and the like), for a
// benchmark to print: how many invocations a multiprocessor can keep in flight follows from them.
#pragma once

#include <string>
#include <vector>

#include "fluidcast/gpu/compute_pipeline.h"
#include "fluidcast/gpu/context.h"

namespace fluidcast::sim {

struct PassStatistics {
  std::string pass;  // the shader's name, as in shaders/sim/
  std::vector<gpu::PipelineStatistic> statistics;
};

// Every pass of the GPU neighbour grid (its count, prefix sum and scatter; the solvers fold the
// count and the scatter into passes of their own on most substeps) and of both solvers, compiled
// on `context`; an empty list for each unless the context captures statistics
// (gpu::ContextOptions::pipeline_statistics).
std::vector<PassStatistics> gpu_solver_pipeline_statistics(gpu::Context& context);

}  // namespace fluidcast::sim

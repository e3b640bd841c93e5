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

// Every pass of the GPU neighbour grid (its count, prefix sum and scatter) and of both solvers,
// compiled on `context`; an empty list for each unless the context captures statistics
// (gpu::ContextOptions::pipeline_statistics). PBF counts and scatters in passes of its own
// (predict, reorder), SPH runs grid_count and scatters in reorder, and only the renderer's
// anisotropy runs grid_scatter.
std::vector<PassStatistics> gpu_solver_pipeline_statistics(gpu::Context& context);

}  // namespace fluidcast::sim

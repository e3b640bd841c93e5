// What every fluidcast benchmark program does around Google Benchmark: `--smoke` asks for one
// small case per benchmark (ctest runs it, so CI proves the benchmark runs), `--device N` picks
// the Vulkan device, `--pipeline-statistics` has the GPU's pipelines keep what the driver says of
// their code (gpu::ContextOptions::pipeline_statistics), and every other flag goes to Google
// Benchmark.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>

#include "fluidcast/gpu/context.h"

namespace fluidcast::bench {

struct BenchOptions {
  bool smoke = false;
  std::optional<std::uint32_t> device;
  bool pipeline_statistics = false;
};

// Calls register_cases, then runs what Google Benchmark's flags select. Returns the exit code.
int run_benchmarks(int argc, char** argv,
                   const std::function<int(const BenchOptions&)>& register_cases);

// For GPU benchmarks: run_benchmarks with a context on the chosen (or best) device, validation
// off, named in the benchmark's context, which gpu_context() gives while they run.
int run_gpu_benchmarks(int argc, char** argv,
                       const std::function<void(bool smoke)>& register_cases);
gpu::Context& gpu_context();

}  // namespace fluidcast::bench

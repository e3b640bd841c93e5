// What every fluidcast benchmark program does around Google Benchmark: `--smoke` asks for one
// small case per benchmark (ctest runs it, so CI proves the benchmark runs), `--device N` picks
// the Vulkan device, and every other flag goes to Google Benchmark.
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
};

// Calls register_cases, then runs what Google Benchmark's flags select. Returns the exit code.
int run_benchmarks(int argc, char** argv,
                   const std::function<int(const BenchOptions&)>& register_cases);

// For GPU benchmarks: a context on the chosen (or best) device, validation off, named in the
// benchmark's context; throws GpuUnavailable as Context does.
std::unique_ptr<gpu::Context> make_bench_context(const BenchOptions& options);

}  // namespace fluidcast::bench

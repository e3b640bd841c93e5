#include "bench_main.h"

#include <benchmark/benchmark.h>

#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

namespace fluidcast::bench {

int run_benchmarks(int argc, char** argv,
                   const std::function<int(const BenchOptions&)>& register_cases) {
  BenchOptions options;
  std::vector<char*> args;
  for (int i = 0; i < argc; ++i) {
    if (std::strcmp(argv[i], "--smoke") == 0) {
      options.smoke = true;
    } else if (std::strcmp(argv[i], "--pipeline-statistics") == 0) {
      options.pipeline_statistics = true;
    } else if (std::strcmp(argv[i], "--device") == 0 && i + 1 < argc) {
      options.device = static_cast<std::uint32_t>(std::stoul(argv[++i]));
    } else {
      args.push_back(argv[i]);
    }
  }
  try {
    if (const int code = register_cases(options); code != 0) return code;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: %s\n", argv[0], e.what());
    return 2;
  }
  int count = static_cast<int>(args.size());
  benchmark::Initialize(&count, args.data());
  if (benchmark::ReportUnrecognizedArguments(count, args.data())) return 2;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}

namespace {
std::unique_ptr<gpu::Context> g_context;
}

int run_gpu_benchmarks(int argc, char** argv,
                       const std::function<void(bool smoke)>& register_cases) {
  const int code = run_benchmarks(argc, argv, [&](const BenchOptions& options) {
    gpu::ContextOptions context_options = gpu::options_from_environment();
    context_options.validation = false;
    if (options.device) context_options.device_index = options.device;
    context_options.pipeline_statistics = options.pipeline_statistics;
    g_context = std::make_unique<gpu::Context>(context_options);
    benchmark::AddCustomContext("device", g_context->info().describe());
    register_cases(options.smoke);
    return 0;
  });
  g_context.reset();
  return code;
}

gpu::Context& gpu_context() { return *g_context; }

}  // namespace fluidcast::bench

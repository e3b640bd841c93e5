// The solver_inputs_fuzz corpus on the GPU solvers: every input the CPU's fuzzing keeps (its seeds
// and what once broke it), run on lavapipe here and on a real device where there is one, with the
// promises solver_inputs.h checks: refused inputs change nothing, the fluid stays finite, inside
// the tank, and a state the solver and the server take back.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <vector>

#include "../fuzz/solver_inputs.h"
#include "gpu_test_support.h"

namespace fluidcast::sim {
namespace {

class GpuSolverInputs : public testing::GpuTest {};

TEST_F(GpuSolverInputs, EveryInputOfTheCpuFuzzingCorpusKeepsTheSolversPromises) {
  const std::filesystem::path corpus = FLUIDCAST_SOLVER_INPUTS_CORPUS;
  int inputs = 0;
  for (const auto& entry : std::filesystem::directory_iterator(corpus)) {
    SCOPED_TRACE(entry.path().filename().string());
    std::ifstream file(entry.path(), std::ios::binary);
    const std::vector<std::uint8_t> input{std::istreambuf_iterator<char>(file),
                                          std::istreambuf_iterator<char>()};
    EXPECT_NO_THROW(fuzzing::run_solver_inputs(
        input.data(), input.size(), [&](SolverKind kind, Scene scene, const SolverParams& params) {
          return make_gpu_solver(kind, context(), std::move(scene), params);
        }));
    ++inputs;
  }
  EXPECT_GT(inputs, 0);
}

}  // namespace
}  // namespace fluidcast::sim

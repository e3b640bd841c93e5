// Fuzz target: any bytes as a small fluid and what a user does to it, on the CPU solvers
// (solver_inputs.h says what is checked). A broken promise escapes as a Defect.
#include <cstddef>
#include <cstdint>

#include "solver_inputs.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace fluidcast::sim;
  fuzzing::run_solver_inputs(data, size,
                             [](SolverKind kind, Scene scene, const SolverParams& params) {
                               return make_cpu_solver(kind, std::move(scene), params);
                             });
  return 0;
}

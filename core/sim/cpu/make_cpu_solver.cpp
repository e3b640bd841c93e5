#include "cpu/pbf_solver.h"
#include "cpu/sph_solver.h"

namespace fluidcast::sim {

std::unique_ptr<Solver> make_cpu_solver(SolverKind kind, Scene scene, const SolverParams& params,
                                        std::shared_ptr<ForkJoinPool> pool) {
  switch (kind) {
    case SolverKind::pbf:
      return std::make_unique<cpu::PbfSolver>(std::move(scene), params, std::move(pool));
    case SolverKind::sph:
      return std::make_unique<cpu::SphSolver>(std::move(scene), params, std::move(pool));
  }
  throw ParamError("{solver}: unknown solver");
}

}  // namespace fluidcast::sim

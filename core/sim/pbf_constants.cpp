#include "pbf_constants.h"

#include <cmath>

#include "fluidcast/sim/kernels.h"

namespace fluidcast::sim {
namespace {

// Σ_j |∇_j C_i|² + |∇_i C_i|² for a particle inside a cubic lattice of spacing d at rest.
float rest_gradient_norm(const Kernels& kernels, const FluidConstants& fluid) {
  const float d = fluid.spacing;
  const int reach = static_cast<int>(std::ceil(kernels.radius() / d));
  const float volume = fluid.rest_volume();
  double sum_squares = 0.0;
  for (int k = -reach; k <= reach; ++k) {
    for (int j = -reach; j <= reach; ++j) {
      for (int i = -reach; i <= reach; ++i) {
        const glm::vec3 r = glm::vec3(i, j, k) * d;
        const glm::vec3 g = volume * kernels.spiky_gradient(r, glm::dot(r, r));
        sum_squares += glm::dot(g, g);
      }
    }
  }
  return static_cast<float>(sum_squares);  // Σ_j ∇W vanishes by the lattice's symmetry
}

}  // namespace

float pbf_correction_weight(const SolverParams& params, int iteration) {
  if (params.iterations < 2) return 1.0f;
  if (iteration == 0) return 1.0f + params.pbf_jacobi_damping;
  if (iteration + 1 == params.iterations) return 1.0f - params.pbf_jacobi_damping;
  return 1.0f;
}

float pbf_step_xsph(const SolverParams& params, int substeps) {
  return 1.0f - std::pow(1.0f - params.xsph_viscosity, static_cast<float>(substeps));
}

PbfConstants derive_pbf_constants(const SolverParams& params, const FluidConstants& fluid) {
  const Kernels kernels(fluid.kernel_radius);
  const float rest_norm = rest_gradient_norm(kernels, fluid);
  const float dq = params.scorr_distance * kernels.radius();
  return {params.relaxation * rest_norm, params.scorr_strength / rest_norm,
          1.0f / kernels.poly6(dq * dq)};
}

}  // namespace fluidcast::sim

#include "substeps.h"

#include <algorithm>
#include <cmath>

namespace fluidcast::sim {

int pbf_substep_count(float step, float largest_speed, float largest_collider_speed, float gravity,
                      const SolverParams& params, float kernel_radius) {
  // A collider moving faster than the fluid sets the pace too: it must not jump over particles.
  const float speed = std::max(largest_speed + gravity * step, largest_collider_speed);
  const float travel = speed * step / (params.cfl_number * kernel_radius);
  if (!std::isfinite(travel)) return params.max_substeps;
  return static_cast<int>(
      std::clamp(std::ceil(travel), 1.0f, static_cast<float>(params.max_substeps)));
}

float sph_stable_substep(float largest_speed, float largest_acceleration,
                         const SolverParams& params, float kernel_radius) {
  const float h = kernel_radius;
  float dt = params.cfl_number * h / (params.sound_speed + largest_speed);
  if (largest_acceleration > 0.0f) dt = std::min(dt, 0.25f * std::sqrt(h / largest_acceleration));
  if (params.sph_viscosity > 0.0f) {
    const float kinematic_viscosity = params.sph_viscosity / params.rest_density;
    dt = std::min(dt, 0.125f * h * h / kinematic_viscosity);
  }
  return dt;
}

}  // namespace fluidcast::sim

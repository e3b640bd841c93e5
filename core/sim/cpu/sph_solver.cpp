#include "cpu/sph_solver.h"

#include <algorithm>
#include <cmath>

#include "substeps.h"

namespace fluidcast::sim::cpu {

float tait_pressure(float density, const SolverParams& params) {
  const float stiffness =
      params.rest_density * params.sound_speed * params.sound_speed / params.tait_exponent;
  const float ratio = density / params.rest_density;
  return std::max(0.0f, stiffness * (std::pow(ratio, params.tait_exponent) - 1.0f));
}

SphSolver::SphSolver(Scene scene, const SolverParams& params, std::shared_ptr<ForkJoinPool> pool)
    : CpuSolver(std::move(scene), params, std::move(pool)),
      min_substep_(params.time_step / static_cast<float>(params.max_substeps)) {}

int SphSolver::substeps_for(float seconds) {
  const float dt = stable_substep(last_max_acceleration_);
  if (!std::isfinite(dt)) return params().max_substeps;
  return static_cast<int>(
      std::clamp(std::ceil(seconds / dt), 1.0f, static_cast<float>(params().max_substeps)));
}

// Each substep as long as the state just computed allows: the planned count is not binding.
int SphSolver::advance(float seconds, int /*planned_substeps*/) {
  float remaining = seconds;
  int taken = 0;
  for (; remaining > 0.0f; ++taken) {
    ++stage_times_.substeps;
    {
      StageTimer timer(stage_times_.grid_ms);
      sort_by(particles_.position, {});
    }
    {
      StageTimer timer(stage_times_.neighbours_ms);
      list_neighbours(particles_.position);
    }
    float max_acceleration;
    {
      StageTimer timer(stage_times_.solve_ms);
      compute_densities_and_pressures();
      max_acceleration = compute_accelerations();
      last_max_acceleration_ = max_acceleration;
    }
    float dt;
    {
      StageTimer timer(stage_times_.velocity_ms);
      dt = std::min(remaining, stable_substep(max_acceleration));
      // Split what is left evenly rather than end on a sliver of a substep.
      if (dt < remaining && remaining < 2.0f * dt) dt = 0.5f * remaining;
    }
    StageTimer timer(stage_times_.predict_ms);
    set_time_into_step(seconds - remaining + dt);
    integrate(dt);
    remaining -= dt;
  }
  return taken;
}

void SphSolver::compute_densities_and_pressures() {
  const std::size_t n = particles_.size();
  density_.resize(n);
  pressure_.resize(n);
  const float mass = fluid().particle_mass;
  const float self = kernels_.poly6(0.0f);
  const auto& x = particles_.position;
  pool_->for_each(n, [&](std::size_t i) {
    density_[i] = mass * (self + neighbour_poly6_sum(x.data(), i)) + walls(x[i]).density;
    pressure_[i] = tait_pressure(density_[i], params());
  });
}

// a_i = g − Σ_j m (p_i/ρ_i² + p_j/ρ_j² + Π_ij) ∇W_ij + μ/ρ_i Σ_j m (v_j − v_i)/ρ_j ∇²W_ij + walls.
// The pressure term is the momentum-conserving form of Becker & Teschner; Müller's
// (p_i + p_j)/(2ρ_j) gives only half of ∇p inside the fluid, which then settles at twice the
// hydrostatic pressure. Π_ij is Monaghan's (1992) artificial viscosity for approaching pairs.
float SphSolver::compute_accelerations() {
  const std::size_t n = particles_.size();
  acceleration_.resize(n);
  chunk_max_acceleration_.assign(pool_->size(), 0.0f);
  const float mass = fluid().particle_mass;
  const float viscosity = params().sph_viscosity;
  const float artificial = 2.0f * params().artificial_viscosity * kernels_.radius() *
                           params().sound_speed;  // ν (ρ_i + ρ_j), h the support radius
  const float softening = 0.01f * kernels_.radius_squared();
  const glm::vec3 g = gravity();
  const auto& x = particles_.position;
  const auto& v = particles_.velocity;
  pool_->for_chunks(n, [&](unsigned chunk, std::size_t begin, std::size_t end) {
    float largest = 0.0f;
    for (std::size_t i = begin; i < end; ++i) {
      const float pressure_term_i = pressure_[i] / (density_[i] * density_[i]);
      lanes::Vec3 pressure_sum{}, viscous_sum{};
      const auto list = neighbours_.blocks_of(i);
      for (std::size_t k = 0; k < list.size(); k += lanes::kWidth) {
        const std::uint32_t* j = list.data() + k;
        const lanes::Vec3 r = offsets(x.data(), i, list, k);
        const lanes::Floats r2 = lanes::dot(r, r);
        const lanes::Floats distance = lanes::sqrt(r2);
        const lanes::Floats density_j = lanes::gather(density_.data(), j);
        const lanes::Vec3 velocity_j = lanes::gather(v.data(), j);
        const lanes::Floats approach = lanes::dot(v[i] - velocity_j, r);
        const lanes::Floats pair = pressure_term_i +
                                   lanes::gather(pressure_.data(), j) / (density_j * density_j) -
                                   lanes::select(approach < 0.0f,
                                                 artificial / (density_[i] + density_j) * approach /
                                                     (distance * distance + softening),
                                                 lanes::Floats{});
        pressure_sum += pair * kernels_.spiky_gradient(r, r2);
        viscous_sum += (kernels_.viscosity_laplacian(distance) / density_j) * (velocity_j - v[i]);
      }
      const glm::vec3 pressure_acceleration = -lanes::sum(pressure_sum);
      // The walls act as the missing fluid, mirrored: same pressure and density as particle i.
      const glm::vec3 wall_acceleration = -2.0f * pressure_term_i * walls(x[i]).gradient;
      const glm::vec3 a = g + mass * pressure_acceleration + wall_acceleration +
                          (viscosity * mass / density_[i]) * lanes::sum(viscous_sum);
      acceleration_[i] = a;
      largest = std::max(largest, glm::length(a));
    }
    chunk_max_acceleration_[chunk] = largest;
  });
  return *std::max_element(chunk_max_acceleration_.begin(), chunk_max_acceleration_.end());
}

float SphSolver::stable_substep(float max_acceleration) {
  return std::max(sph_stable_substep(max_speed(), max_acceleration, params(), kernels_.radius()),
                  min_substep_);
}

// Symplectic Euler, then the boundaries.
void SphSolver::integrate(float dt) {
  pool_->for_each(particles_.size(), [&](std::size_t i) {
    glm::vec3& v = particles_.velocity[i];
    glm::vec3& x = particles_.position[i];
    v = held_to_max_speed(v + dt * acceleration_[i]);
    x += dt * v;
    constrain_position_and_velocity(x, v);
    // After the colliders, which may add speed: a finger's into a particle's own across it.
    v = held_to_max_speed(v);
  });
}

}  // namespace fluidcast::sim::cpu

#include "cpu/cpu_solver.h"

#include <algorithm>
#include <cmath>

namespace fluidcast::sim::cpu {

CpuSolver::CpuSolver(Scene scene, const SolverParams& params, std::shared_ptr<ForkJoinPool> pool)
    : Solver(std::move(scene), params),
      pool_(pool ? std::move(pool)
                 : std::make_shared<ForkJoinPool>(static_cast<unsigned>(params.threads))),
      kernels_(fluid().kernel_radius),
      grid_(tank(), fluid().kernel_radius) {
  inner_tank_ = inner_tank();
  wall_fluid_box_ = fluid().wall_fluid_box(tank());
  load_particles(this->scene().particles);
}

void CpuSolver::load_particles(const ParticleSet& particles) { particles_ = particles; }

void CpuSolver::append_particles(std::span<const glm::vec3> positions,
                                 std::span<const glm::vec3> velocities, std::uint32_t first_id) {
  for (std::size_t i = 0; i < positions.size(); ++i) {
    particles_.append(positions[i], velocities[i], first_id + static_cast<std::uint32_t>(i));
  }
}

std::size_t CpuSolver::erase_particles_in_sphere(glm::vec3 centre, float radius) {
  const float r2 = radius * radius;
  std::size_t kept = 0;
  for (std::size_t i = 0; i < particles_.size(); ++i) {
    const glm::vec3 d = particles_.position[i] - centre;
    if (glm::dot(d, d) <= r2) continue;
    particles_.position[kept] = particles_.position[i];
    particles_.velocity[kept] = particles_.velocity[i];
    particles_.id[kept] = particles_.id[i];
    ++kept;
  }
  const std::size_t removed = particles_.size() - kept;
  particles_.position.resize(kept);
  particles_.velocity.resize(kept);
  particles_.id.resize(kept);
  return removed;
}

void CpuSolver::sort_by(std::vector<glm::vec3>& key,
                        std::initializer_list<std::vector<glm::vec3>*> solver_arrays) {
  grid_.build(*pool_, key);
  const auto order = grid_.order();
  apply_order(*pool_, order, particles_.position, reorder_scratch_);
  apply_order(*pool_, order, particles_.velocity, reorder_scratch_);
  apply_order(*pool_, order, particles_.id, id_scratch_);
  for (auto* array : solver_arrays) apply_order(*pool_, order, *array, reorder_scratch_);
}

void CpuSolver::list_neighbours(std::span<const glm::vec3> sorted) {
  neighbours_.build(*pool_, grid_, sorted, kernels_.radius(), fluid().max_candidates,
                    fluid().max_neighbours);
}

float CpuSolver::max_speed() {
  chunk_max_.assign(pool_->size(), 0.0f);
  pool_->for_chunks(particles_.size(), [&](unsigned chunk, std::size_t begin, std::size_t end) {
    float largest = 0.0f;
    for (std::size_t i = begin; i < end; ++i) {
      largest = std::max(largest, glm::dot(particles_.velocity[i], particles_.velocity[i]));
    }
    chunk_max_[chunk] = largest;
  });
  return std::sqrt(*std::max_element(chunk_max_.begin(), chunk_max_.end()));
}

namespace {

// Moves p onto the surface of each collider it is inside, calling on_contact(normal, collider).
template <class OnContact>
glm::vec3 push_out_of_colliders(glm::vec3 p, std::span<const Collider> colliders, float time,
                                float particle_radius, OnContact&& on_contact) {
  for (const Collider& c : colliders) {
    const glm::vec3 centre = c.centre + time * c.velocity;
    const glm::vec3 d = p - centre;
    const float reach = c.radius + particle_radius;
    const float dist2 = glm::dot(d, d);
    if (!(dist2 < reach * reach)) continue;  // NaN stays NaN, to be counted, not hidden
    const float dist = std::sqrt(dist2);
    // A particle at the very centre has no direction out: send it up.
    const glm::vec3 normal = dist > 1e-6f * reach ? d / dist : glm::vec3(0, 1, 0);
    p = centre + normal * reach;
    on_contact(normal, c);
  }
  return p;
}

}  // namespace

float CpuSolver::max_collider_speed() const {
  float fastest = 0.0f;
  for (const Collider& c : colliders()) fastest = std::max(fastest, glm::length(c.velocity));
  return fastest;
}

glm::vec3 CpuSolver::constrain_position(glm::vec3 p) const {
  p = push_out_of_colliders(p, colliders(), time_into_step_, fluid().particle_radius(),
                            [](glm::vec3, const Collider&) {});
  return glm::clamp(p, inner_tank_.min, inner_tank_.max);
}

void CpuSolver::constrain_position_and_velocity(glm::vec3& p, glm::vec3& v) const {
  p = push_out_of_colliders(p, colliders(), time_into_step_, fluid().particle_radius(),
                            [&](glm::vec3 normal, const Collider& c) {
                              const float approach = glm::dot(v - c.velocity, normal);
                              if (approach < 0.0f) v -= approach * normal;
                            });
  for (int axis = 0; axis < 3; ++axis) {
    if (p[axis] < inner_tank_.min[axis]) {
      p[axis] = inner_tank_.min[axis];
      v[axis] = std::max(v[axis], 0.0f);
    } else if (p[axis] > inner_tank_.max[axis]) {
      p[axis] = inner_tank_.max[axis];
      v[axis] = std::min(v[axis], 0.0f);
    }
  }
}

}  // namespace fluidcast::sim::cpu

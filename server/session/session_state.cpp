// Session: its state as clients see it, and snapshots out and in.
#include <cmath>

#include "fluidcast/gpu/vk_check.h"
#include "fluidcast/sim/param_spec.h"
#include "input_rules.h"
#include "session.h"
#include "validation.h"

namespace fluidcast::server {
namespace {

v1::Vec3 vec3(glm::vec3 v) {
  v1::Vec3 out;
  out.set_x(v.x);
  out.set_y(v.y);
  out.set_z(v.z);
  return out;
}

struct Particles {
  std::vector<glm::vec3> position, velocity;
};

// A snapshot's particles, each finite, inside `tank` and not faster than the solvers allow;
// throws a Refusal naming what is wrong.
Particles checked_particles(const v1::Snapshot& snapshot, std::uint32_t max_particles,
                            const sim::Box& tank) {
  const int values = snapshot.positions_size();
  if (values % 3 != 0 || snapshot.velocities_size() != values) {
    throw Refusal(RefusalCode::invalid_argument,
                  "Snapshot: positions and velocities need three values per particle each");
  }
  const std::size_t count = static_cast<std::size_t>(values / 3);
  if (count == 0) throw Refusal(RefusalCode::invalid_argument, "Snapshot has no particles");
  if (count > max_particles) {
    throw Refusal(RefusalCode::resource_exhausted,
                  "Snapshot: " + std::to_string(count) +
                      " particles are more than this server's limit of " +
                      std::to_string(max_particles));
  }
  Particles particles{std::vector<glm::vec3>(count), std::vector<glm::vec3>(count)};
  for (std::size_t k = 0; k < count; ++k) {
    glm::vec3& p = particles.position[k];
    glm::vec3& v = particles.velocity[k];
    for (int axis = 0; axis < 3; ++axis) {
      p[axis] = snapshot.positions(static_cast<int>(3 * k) + axis);
      v[axis] = snapshot.velocities(static_cast<int>(3 * k) + axis);
    }
    if (!std::isfinite(p.x + p.y + p.z) || !std::isfinite(v.x + v.y + v.z) ||
        glm::any(glm::lessThan(p, tank.min)) || glm::any(glm::greaterThan(p, tank.max)) ||
        !sim::within_limit(v, sim::kMaxSpeed)) {
      throw Refusal(RefusalCode::invalid_argument,
                    "Snapshot: particle " + std::to_string(k) +
                        " is not finite, outside the tank, or faster than " +
                        std::to_string(int(sim::kMaxSpeed)) + " m/s");
    }
  }
  return particles;
}

}  // namespace

v1::SessionState Session::state() const {
  v1::SessionState state;
  state.set_scene(std::string(sim::to_string(setup_.scene)));
  state.set_solver(std::string(sim::to_string(setup_.solver)));
  state.set_particles(static_cast<std::uint32_t>(solver_->particle_count()));
  state.set_paused(paused_);
  state.set_particle_spacing(solver_->scene().spacing);
  *state.mutable_tank()->mutable_min() = vec3(solver_->tank().min);
  *state.mutable_tank()->mutable_max() = vec3(solver_->tank().max);
  return state;
}

v1::Snapshot Session::snapshot() const {
  const sim::ParticleSet particles = solver_->snapshot();
  v1::Snapshot snapshot;
  snapshot.set_time(solver_->time());
  *snapshot.mutable_gravity() = vec3(solver_->gravity());
  snapshot.set_scene(std::string(sim::to_string(setup_.scene)));
  snapshot.set_solver(std::string(sim::to_string(setup_.solver)));
  snapshot.mutable_positions()->Reserve(static_cast<int>(3 * particles.size()));
  snapshot.mutable_velocities()->Reserve(static_cast<int>(3 * particles.size()));
  for (std::size_t k = 0; k < particles.size(); ++k) {
    for (int axis = 0; axis < 3; ++axis) {
      snapshot.add_positions(particles.position[k][axis]);
      snapshot.add_velocities(particles.velocity[k][axis]);
    }
  }
  return snapshot;
}

std::uint32_t Session::load(const v1::Snapshot& snapshot) {
  const auto started = Clock::now();
  // Checked before the fluid is touched: a refused snapshot leaves the session as it was.
  const Particles particles =
      checked_particles(snapshot, services_.limits->max_particles, solver_->tank());
  try {
    sim::check_density(particles.position, solver_->fluid());
  } catch (const std::invalid_argument& e) {
    throw Refusal(RefusalCode::invalid_argument, std::string("Snapshot: ") + e.what());
  }
  std::optional<glm::vec3> gravity;
  if (snapshot.has_gravity()) {
    gravity = glm::vec3(snapshot.gravity().x(), snapshot.gravity().y(), snapshot.gravity().z());
    if (!std::isfinite(gravity->x + gravity->y + gravity->z) ||
        !sim::within_limit(*gravity, sim::kMaxGravity)) {
      throw Refusal(RefusalCode::invalid_argument, "Snapshot: gravity is not finite or too large");
    }
  }
  validate_snapshot_time(snapshot.time(), "Snapshot.time");
  const glm::vec3 gravity_before = solver_->gravity();
  try {
    // Gravity first: the substep rule starts from the new fluid's weight along it.
    if (gravity) solver_->set_gravity(*gravity);
    solver_->replace_particles(particles.position, particles.velocity);
  } catch (const sim::ParamError& e) {  // the checks above passed: more than the GPU solver holds
    solver_->set_gravity(gravity_before);
    throw Refusal(RefusalCode::resource_exhausted,
                  e.worded([](std::string_view) { return std::string("Snapshot"); }));
  } catch (const std::invalid_argument& e) {
    solver_->set_gravity(gravity_before);
    throw Refusal(RefusalCode::invalid_argument, std::string("Snapshot: ") + e.what());
  } catch (const gpu::VulkanError& e) {  // within the budget, but other sessions hold the memory
    solver_->set_gravity(gravity_before);
    if (!e.out_of_memory()) throw;
    throw no_gpu_memory("Snapshot", std::to_string(particles.position.size()) + " particles", e,
                        "send fewer, or later");
  }
  forget_costs();  // another count: another cost
  fingers_.clear();
  solver_->set_time(snapshot.time());
  speed_.restart();  // the clock jumped: no speed is measured across it
  charge_worker_time(started);
  return static_cast<std::uint32_t>(particles.position.size());
}

}  // namespace fluidcast::server

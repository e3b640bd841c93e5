// Session: its state as clients see it, and snapshots out and in.
#include <cmath>

#include "fluidcast/sim/param_spec.h"
#include "input_rules.h"
#include "session.h"

namespace fluidcast::server {
namespace {

v1::Vec3 vec3(glm::vec3 v) {
  v1::Vec3 out;
  out.set_x(v.x);
  out.set_y(v.y);
  out.set_z(v.z);
  return out;
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
  const int values = snapshot.positions_size();
  if (values % 3 != 0 || snapshot.velocities_size() != values) {
    throw Refusal(RefusalCode::invalid_argument,
                  "Snapshot: positions and velocities need three values per particle each");
  }
  const std::size_t count = static_cast<std::size_t>(values / 3);
  if (count > services_.limits->max_particles) {
    throw Refusal(RefusalCode::resource_exhausted,
                  std::to_string(count) + " particles are more than this server's limit of " +
                      std::to_string(services_.limits->max_particles));
  }
  std::vector<glm::vec3> positions(count), velocities(count);
  for (std::size_t k = 0; k < count; ++k) {
    for (int axis = 0; axis < 3; ++axis) {
      positions[k][axis] = snapshot.positions(static_cast<int>(3 * k) + axis);
      velocities[k][axis] = snapshot.velocities(static_cast<int>(3 * k) + axis);
    }
  }
  // Checked before the fluid is touched: a refused snapshot leaves the session as it was.
  const sim::Box& box = solver_->tank();
  for (std::size_t k = 0; k < count; ++k) {
    const glm::vec3 p = positions[k], v = velocities[k];
    if (!std::isfinite(p.x + p.y + p.z) || !std::isfinite(v.x + v.y + v.z) ||
        glm::any(glm::lessThan(p, box.min)) || glm::any(glm::greaterThan(p, box.max)) ||
        !sim::within_limit(v, sim::kMaxSpeed)) {
      throw Refusal(RefusalCode::invalid_argument,
                    "Snapshot: particle " + std::to_string(k) +
                        " is not finite, outside the tank, or faster than " +
                        std::to_string(int(sim::kMaxSpeed)) + " m/s");
    }
  }
  try {
    sim::check_density(positions, solver_->fluid());
  } catch (const std::invalid_argument& e) {
    throw Refusal(RefusalCode::invalid_argument, std::string("Snapshot: ") + e.what());
  }
  if (snapshot.has_gravity()) {
    const glm::vec3 g(snapshot.gravity().x(), snapshot.gravity().y(), snapshot.gravity().z());
    if (!std::isfinite(g.x + g.y + g.z) || !sim::within_limit(g, sim::kMaxGravity)) {
      throw Refusal(RefusalCode::invalid_argument, "Snapshot: gravity is not finite or too large");
    }
  }
  if (!(std::isfinite(snapshot.time()) && snapshot.time() >= 0.0)) {
    throw Refusal(RefusalCode::invalid_argument, "Snapshot: time must be finite, not negative");
  }
  const sim::Box tank = solver_->tank();
  const glm::vec3 centre = 0.5f * (tank.min + tank.max);
  forget_costs();  // another count: another cost
  solver_->remove_particles_in_sphere(centre, glm::length(tank.size()));
  try {
    solver_->add_particles(positions, velocities);
    solver_->set_time(snapshot.time());
    if (snapshot.has_gravity()) {
      solver_->set_gravity(
          {snapshot.gravity().x(), snapshot.gravity().y(), snapshot.gravity().z()});
    }
  } catch (const std::invalid_argument& e) {
    solver_->reset();
    throw Refusal(RefusalCode::invalid_argument, std::string("Snapshot: ") + e.what());
  }
  return static_cast<std::uint32_t>(count);
}

}  // namespace fluidcast::server

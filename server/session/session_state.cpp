// Session: its state as clients see it, and snapshots out and in.
#include <cmath>
#include <optional>
#include <span>

#include "fluidcast/gpu/vk_check.h"
#include "fluidcast/sim/fluid_constants.h"
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

// A vector as a client reads it back: (x, y, z) in six significant digits.
std::string text(glm::vec3 v) {
  return "(" + sim::format_number(v.x) + ", " + sim::format_number(v.y) + ", " +
         sim::format_number(v.z) + ")";
}

struct Particles {
  std::vector<glm::vec3> position, velocity;
};

// How many particles a snapshot holds; throws a Refusal where its values do not make particles
// or make more than `max_particles`.
std::uint32_t particle_count(const v1::Snapshot& snapshot, std::uint32_t max_particles) {
  const int values = snapshot.positions_size();
  if (values % 3 != 0 || snapshot.velocities_size() != values) {
    throw Refusal(RefusalCode::invalid_argument,
                  "Snapshot: positions and velocities need three values per particle each");
  }
  const auto count = static_cast<std::uint32_t>(values / 3);
  if (count == 0) throw Refusal(RefusalCode::invalid_argument, "Snapshot has no particles");
  if (count > max_particles) {
    throw Refusal(RefusalCode::resource_exhausted,
                  "Snapshot: " + std::to_string(count) +
                      " particles are more than this server's limit of " +
                      std::to_string(max_particles));
  }
  return count;
}

// A snapshot's `count` particles (particle_count()), each finite, inside `tank` and not faster
// than the solvers allow; throws a Refusal naming what is wrong.
Particles checked_particles(const v1::Snapshot& snapshot, std::uint32_t count,
                            const sim::Box& tank) {
  Particles particles{std::vector<glm::vec3>(count), std::vector<glm::vec3>(count)};
  for (std::size_t k = 0; k < count; ++k) {
    glm::vec3& p = particles.position[k];
    glm::vec3& v = particles.velocity[k];
    for (int axis = 0; axis < 3; ++axis) {
      p[axis] = snapshot.positions(static_cast<int>(3 * k) + axis);
      v[axis] = snapshot.velocities(static_cast<int>(3 * k) + axis);
    }
    const auto particle = [k] { return "Snapshot: particle " + std::to_string(k) + "'s "; };
    if (!std::isfinite(p.x + p.y + p.z) || glm::any(glm::lessThan(p, tank.min)) ||
        glm::any(glm::greaterThan(p, tank.max))) {
      throw Refusal(RefusalCode::invalid_argument,
                    particle() + "position " + text(p) + " is not inside the tank, " +
                        text(tank.min) + " to " + text(tank.max) + " m (SessionState.tank)");
    }
    if (!std::isfinite(v.x + v.y + v.z) || !sim::within_limit(v, sim::kMaxSpeed)) {
      throw Refusal(RefusalCode::invalid_argument,
                    particle() + "velocity " + text(v) + " is faster than " +
                        sim::format_number(sim::kMaxSpeed) + " m/s, or not finite");
    }
  }
  return particles;
}

// Puts the particles (their density checked) into `solver`, under `gravity` where the snapshot
// has one; throws a Refusal naming what does not fit, and the solver keeps its gravity.
void put_particles(sim::Solver& solver, std::span<const glm::vec3> positions,
                   std::span<const glm::vec3> velocities, std::optional<glm::vec3> gravity) {
  const glm::vec3 gravity_before = solver.gravity();
  try {
    // Gravity first: the substep rule starts from the new fluid's weight along it.
    if (gravity) solver.set_gravity(*gravity);
    solver.replace_particles(positions, velocities);
  } catch (const sim::ParamError& e) {  // the checks passed: more than the GPU solver holds
    solver.set_gravity(gravity_before);
    throw Refusal(RefusalCode::resource_exhausted,
                  e.worded([](std::string_view) { return std::string("Snapshot"); }));
  } catch (const std::invalid_argument& e) {
    solver.set_gravity(gravity_before);
    throw Refusal(RefusalCode::invalid_argument, std::string("Snapshot: ") + e.what());
  } catch (const gpu::VulkanError& e) {  // within the budget, but other sessions hold the memory
    solver.set_gravity(gravity_before);
    if (!e.out_of_memory()) throw;
    throw no_gpu_memory("Snapshot", std::to_string(positions.size()) + " particles", e,
                        "send fewer, or later");
  }
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

v1::Snapshot Session::snapshot() {
  const auto started = Clock::now();
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
  charge_worker_time(started);
  return snapshot;
}

std::uint32_t Session::load(const v1::Snapshot& snapshot) {
  const auto started = Clock::now();
  try {
    const std::uint32_t particles = replace_fluid(snapshot);
    charge_worker_time(started);
    return particles;
  } catch (...) {
    charge_worker_time(started);  // a refused state cost the worker too
    throw;
  }
}

std::uint32_t Session::replace_fluid(const v1::Snapshot& snapshot) {
  // Checked before the fluid is touched, and before a solver is built for it: a refused snapshot
  // leaves the session as it was, and costs no solver.
  const std::uint32_t count = particle_count(snapshot, services_.limits->max_particles);
  SessionSetup setup = setup_;
  if (!snapshot.scene().empty()) {
    validate_scene(snapshot.scene(), "Snapshot.scene");
    setup.scene = sim::parse_scene(snapshot.scene());
  }
  if (!snapshot.solver().empty()) {
    validate_solver(snapshot.solver(), "Snapshot.solver");
    setup.solver = sim::parse_solver(snapshot.solver());
  }
  setup.particles = count;
  std::optional<glm::vec3> gravity;
  if (snapshot.has_gravity()) {
    gravity = glm::vec3(snapshot.gravity().x(), snapshot.gravity().y(), snapshot.gravity().z());
    // What a Tilt may set, the one gravity a session's fluid can have had: turned into the
    // tank's axes, its length may come out an ulp or two past either end (within_limit).
    const float magnitude = glm::length(*gravity);
    if (!(magnitude >= kMinTiltGravity * (1.0f - 1e-6f) &&
          sim::within_limit(*gravity, kMaxTiltGravity))) {
      throw Refusal(RefusalCode::invalid_argument,
                    "Snapshot.gravity " + text(*gravity) + " must be finite with a magnitude of " +
                        sim::format_number(kMinTiltGravity) + " to " +
                        sim::format_number(kMaxTiltGravity) + " m/s² (InputRules.tilt_gravity)");
    }
  }
  validate_snapshot_time(snapshot.time(), "Snapshot.time");
  // A scene's particles are spaced for its water's volume and their count: a fluid of another
  // scene or count, loaded into this one's solver, would be squeezed or stretched to its rest
  // density. It goes into a solver built for it (the first fluid too), once it passed the checks
  // that need no solver.
  std::optional<sim::Scene> scene;
  if (!solver_ || !(setup == setup_)) scene = scene_for(setup);
  const Particles particles =
      checked_particles(snapshot, count, scene ? scene->tank : solver_->tank());
  try {
    sim::check_density(
        particles.position,
        scene ? sim::derive_fluid_constants(scene->spacing, solver_params()) : solver_->fluid());
  } catch (const std::invalid_argument& e) {
    throw Refusal(RefusalCode::invalid_argument, std::string("Snapshot: ") + e.what());
  }
  std::unique_ptr<sim::Solver> built = scene ? build_solver(setup, *std::move(scene)) : nullptr;
  sim::Solver& target = built ? *built : *solver_;
  try {
    put_particles(target, particles.position, particles.velocity, gravity);
  } catch (...) {
    if (built) retire_solver(std::move(built));
    throw;
  }
  // The newest state wins over wishes and a reset that were waiting for their turn; a viewer
  // whose menu shows its wish is told what came instead.
  const bool wish_dropped = setup_wanted_.has_value();
  setup_wanted_.reset();
  wish_askers_ = {};
  reset_wanted_ = false;
  if (built) {
    if (solver_) last_rebuild_ = Clock::now();  // the first fluid is no rebuild
    adopt(std::move(built), setup);
  } else {
    forget_costs();  // another fluid: another cost
    fingers_.clear();
    if (wish_dropped) tell_state();
  }
  solver_->set_time(snapshot.time());
  speed_.restart();  // the clock jumped: no speed is measured across it
  return static_cast<std::uint32_t>(particles.position.size());
}

}  // namespace fluidcast::server

#include "fluidcast/sim/solver.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>
#include <unordered_map>

#include "fluidcast/sim/neighbour_grid.h"

namespace fluidcast::sim {
namespace {

std::string str(glm::vec3 v) {
  std::ostringstream out;
  out << '(' << v.x << ", " << v.y << ", " << v.z << ')';
  return out.str();
}

void require(bool ok, const std::string& message) {
  if (!ok) throw std::invalid_argument(message);
}

// What is wrong with a gravity, in words; empty when nothing is.
std::string gravity_problem(glm::vec3 gravity) {
  if (!is_finite(gravity)) return "every component must be finite, got " + str(gravity);
  if (!within_limit(gravity, kMaxGravity)) {
    return "magnitude " + std::to_string(glm::length(gravity)) + " m/s² exceeds " +
           std::to_string(kMaxGravity) + " m/s²";
  }
  return {};
}

}  // namespace

const std::vector<std::string_view>& solver_names() {
  static const std::vector<std::string_view> names = {"pbf", "sph"};
  return names;
}

std::string_view to_string(SolverKind kind) { return solver_names()[static_cast<int>(kind)]; }

SolverKind parse_solver(std::string_view name) {
  return static_cast<SolverKind>(index_of_name(solver_names(), name, "solver", "solver"));
}

Solver::Solver(Scene scene, const SolverParams& params)
    : scene_(std::move(scene)), params_(params), gravity_(scene_.gravity) {
  validate(params_);
  if (const std::string problem = gravity_problem(gravity_); !problem.empty()) {
    throw ParamError("scene: gravity: " + problem);
  }
  const ParticleSet& p = scene_.particles;
  if (!std::isfinite(scene_.spacing) || scene_.spacing <= 0.0f) {
    throw ParamError("scene: particle spacing must be positive and finite, got " +
                     std::to_string(scene_.spacing));
  }
  if (p.velocity.size() != p.size() || p.id.size() != p.size()) {
    throw ParamError("scene: positions, velocities and ids differ in count");
  }
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (!is_finite(p.position[i]) || !scene_.tank.contains(p.position[i])) {
      throw ParamError("scene: particle " + std::to_string(i) + " at " + str(p.position[i]) +
                       " is not finite or not inside the tank " + str(scene_.tank.min) + "–" +
                       str(scene_.tank.max));
    }
    // As for particles added later (check_new_particles): SPH's viscosity overflowed on 1e36 m/s.
    if (!is_finite(p.velocity[i]) || !within_limit(p.velocity[i], kMaxSpeed)) {
      throw ParamError("scene: particle " + std::to_string(i) + "'s velocity " +
                       str(p.velocity[i]) + " must be finite with magnitude at most " +
                       format_number(kMaxSpeed) + " m/s");
    }
  }
  fluid_ = derive_fluid_constants(scene_.spacing, params_);
  const glm::vec3 size = scene_.tank.size();
  if (std::min({size.x, size.y, size.z}) < fluid_.spacing) {
    throw ParamError("{particles}, {tank-length}, {tank-height}, {depth}: the tank " + str(size) +
                     " m is thinner than one particle spacing (" + std::to_string(fluid_.spacing) +
                     " m) in some direction; use more particles or a larger tank");
  }
  const glm::vec3 cells = glm::ceil(size * (NeighbourGrid::kCellsPerRadius / fluid_.kernel_radius));
  const double cell_count = double(cells.x) * cells.y * cells.z;
  if (cell_count > double(NeighbourGrid::kMaxCells)) {
    throw ParamError(
        "{particles}, {tank-length}, {tank-height}, {depth}: the neighbour grid would "
        "need " +
        std::to_string(static_cast<long long>(cell_count)) + " cells of half the kernel radius " +
        std::to_string(fluid_.kernel_radius) + " m, over the limit of " +
        std::to_string(NeighbourGrid::kMaxCells) + "; use fewer particles or a smaller tank");
  }
  if (scene_.particles.size() > static_cast<std::size_t>(params_.max_particles)) {
    throw ParamError("{particles}: the scene has " + std::to_string(scene_.particles.size()) +
                     " particles, more than {max-particles} " +
                     std::to_string(params_.max_particles));
  }
  next_id_ = static_cast<std::uint32_t>(scene_.particles.size());
}

int Solver::step(float seconds, int substeps) {
  require(seconds > 0.0f && seconds <= params_.time_step,
          "step: " + format_number(seconds) + " s is not in (0, " +
              format_number(params_.time_step) + "] s, the time step");
  require(substeps >= 1 && substeps <= params_.max_substeps,
          "step: " + std::to_string(substeps) + " substeps are not in [1, " +
              std::to_string(params_.max_substeps) + "]");
  require(seconds / float(substeps) >= kShortestSubstep,
          "step: " + format_number(seconds) + " s in " + std::to_string(substeps) +
              " substeps is less than " + format_number(kShortestSubstep) + " s a substep");
  const int taken = advance(seconds, substeps);
  for (Collider& c : colliders_) c.centre += c.velocity * seconds;
  ++steps_;
  time_ += seconds;
  return taken;
}

Box Solver::inner_tank() const {
  const glm::vec3 r(fluid_.particle_radius());
  return {scene_.tank.min + r, scene_.tank.max - r};
}

void Solver::set_gravity(glm::vec3 gravity) {
  const std::string problem = gravity_problem(gravity);
  require(problem.empty(), "gravity: " + problem);
  gravity_ = gravity;
}

void Solver::set_colliders(std::span<const Collider> colliders) {
  require(colliders.size() <= kMaxColliders, "colliders: " + std::to_string(colliders.size()) +
                                                 " given, at most " +
                                                 std::to_string(kMaxColliders) + " allowed");
  for (std::size_t i = 0; i < colliders.size(); ++i) {
    const Collider& c = colliders[i];
    const std::string name = "collider " + std::to_string(i);
    require(is_finite(c.centre), name + ": centre must be finite, got " + str(c.centre));
    require(std::isfinite(c.radius) && c.radius > 0.0f && c.radius <= kMaxColliderRadius,
            name + ": radius must be in (0, " + std::to_string(kMaxColliderRadius) + "] m, got " +
                std::to_string(c.radius));
    require(is_finite(c.velocity) && within_limit(c.velocity, kMaxSpeed),
            name + ": velocity must be finite with magnitude at most " + std::to_string(kMaxSpeed) +
                " m/s, got " + str(c.velocity));
  }
  colliders_.assign(colliders.begin(), colliders.end());
}

void Solver::check_new_particles(std::string_view what, std::span<const glm::vec3> positions,
                                 std::span<const glm::vec3> velocities, std::size_t total) const {
  const std::string name(what);
  require(positions.size() == velocities.size(),
          name + ": " + std::to_string(positions.size()) + " positions but " +
              std::to_string(velocities.size()) + " velocities");
  require(total <= static_cast<std::size_t>(params_.max_particles),
          name + ": " + std::to_string(positions.size()) + " given would make " +
              std::to_string(total) + " particles; the limit is " +
              std::to_string(params_.max_particles) + " (--max-particles)");
  for (std::size_t i = 0; i < positions.size(); ++i) {
    require(is_finite(positions[i]) && scene_.tank.contains(positions[i]),
            name + ": position " + std::to_string(i) + " " + str(positions[i]) +
                " is not inside the tank " + str(scene_.tank.min) + "–" + str(scene_.tank.max));
    require(is_finite(velocities[i]) && within_limit(velocities[i], kMaxSpeed),
            name + ": velocity " + std::to_string(i) + " " + str(velocities[i]) +
                " must be finite with magnitude at most " + std::to_string(kMaxSpeed) + " m/s");
  }
}

void Solver::add_particles(std::span<const glm::vec3> positions,
                           std::span<const glm::vec3> velocities) {
  check_new_particles("add_particles", positions, velocities, particle_count() + positions.size());
  append_particles(positions, velocities, next_id_);
  next_id_ += static_cast<std::uint32_t>(positions.size());
}

void Solver::replace_particles(std::span<const glm::vec3> positions,
                               std::span<const glm::vec3> velocities) {
  check_new_particles("replace_particles", positions, velocities, positions.size());
  ParticleSet fluid;
  for (std::size_t i = 0; i < positions.size(); ++i) {
    fluid.append(positions[i], velocities[i], static_cast<std::uint32_t>(i));
  }
  load_particles(fluid);
  next_id_ = static_cast<std::uint32_t>(positions.size());
}

std::size_t Solver::remove_particles_in_sphere(glm::vec3 centre, float radius) {
  require(is_finite(centre), "remove_particles: centre must be finite, got " + str(centre));
  require(
      std::isfinite(radius) && radius >= 0.0f,
      "remove_particles: radius must be finite and not negative, got " + std::to_string(radius));
  return erase_particles_in_sphere(centre, radius);
}

void check_density(std::span<const glm::vec3> positions, const FluidConstants& fluid) {
  const float side = 2.0f * fluid.kernel_radius;
  const float at_rest = std::pow(side / fluid.spacing, 3.0f);
  const auto most = static_cast<std::uint32_t>(kMaxDensityRatio * at_rest);
  // Cubes counted from the positions' lowest corner, 21 bits an axis in one key.
  constexpr double kCubesPerAxis = double(1u << 21);
  glm::vec3 lowest(std::numeric_limits<float>::max()), highest(-std::numeric_limits<float>::max());
  for (const glm::vec3& p : positions) {
    if (!is_finite(p)) throw std::invalid_argument("a position is not finite: " + str(p));
    lowest = glm::min(lowest, p);
    highest = glm::max(highest, p);
  }
  if (!positions.empty() &&
      glm::any(glm::greaterThanEqual(glm::dvec3(highest - lowest) / double(side),
                                     glm::dvec3(kCubesPerAxis)))) {
    throw std::invalid_argument("positions spread over more than " +
                                std::to_string(kCubesPerAxis * side) + " m: " + str(lowest) +
                                " to " + str(highest));
  }
  std::unordered_map<std::uint64_t, std::uint32_t> per_cube;
  per_cube.reserve(positions.size());
  for (const glm::vec3& p : positions) {
    const glm::uvec3 cube(glm::floor(glm::dvec3(p - lowest) / double(side)));
    const std::uint64_t key =
        (std::uint64_t(cube.x) << 42) | (std::uint64_t(cube.y) << 21) | std::uint64_t(cube.z);
    if (++per_cube[key] > most) {
      const glm::vec3 corner = lowest + glm::vec3(cube) * side;
      throw std::invalid_argument(
          "more than " + std::to_string(most) + " particles in the " + std::to_string(side) +
          " m cube at " + str(corner) + ": over " + std::to_string(int(kMaxDensityRatio)) +
          " times the fluid's rest density (" + std::to_string(int(at_rest)) +
          " there), a state no fluid reaches");
    }
  }
}

void Solver::set_time(double seconds) {
  if (!(std::isfinite(seconds) && seconds >= 0.0)) {
    throw std::invalid_argument("the simulated time must be finite and not negative");
  }
  time_ = seconds;
}

void Solver::reset() {
  load_particles(scene_.particles);
  time_ = 0.0;
  steps_ = 0;
  next_id_ = static_cast<std::uint32_t>(scene_.particles.size());
}

}  // namespace fluidcast::sim

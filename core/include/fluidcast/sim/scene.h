// The starting states a user can pick. All sizes in metres; the tank's inner box starts at the
// origin: x along its length, y up, z across its depth.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "fluidcast/sim/param_spec.h"
#include "fluidcast/sim/particles.h"

namespace fluidcast::sim {

enum class SceneKind { dam_break, double_dam_break, drop, pool };

const std::vector<std::string_view>& scene_names();
SceneKind parse_scene(std::string_view name);  // throws ParamError listing the names
std::string_view to_string(SceneKind kind);

struct SceneParams {
  SceneKind kind = SceneKind::dam_break;
  int particles = 20000;
  float tank_length = 1.6f;    // x
  float tank_height = 1.0f;    // y, the lid
  float depth = 0.3f;          // z; dam-break columns fill all of it
  float column_width = 0.4f;   // x extent of a dam-break column
  float column_height = 0.8f;  // y extent of a dam-break column
  float pool_height = 0.3f;    // pool and drop: height of the resting water
  float drop_radius = 0.12f;   // drop: radius of the falling ball
  float drop_height = 0.7f;    // drop: height of the ball's centre above the floor
};

const std::vector<ParamSpec<SceneParams>>& scene_param_specs();

// Throws ParamError for a value out of range or a geometry that does not fit the tank.
void validate(const SceneParams& params);

// m/s²: the tank upright on the ground.
inline constexpr glm::vec3 kStandardGravity{0.0f, -9.81f, 0.0f};

struct Scene {
  SceneParams params;
  Box tank;
  float spacing = 0.0f;  // d: the lattice spacing of the initial particles
  ParticleSet particles;
  // What the particles start falling under, m/s²: a solver built on the scene starts under it
  // (a fluid built while the tank is tilted, under the tilt), and PBF's substep rule from its
  // weight along it. Solver::set_gravity changes the gravity afterwards; reset() keeps that one.
  glm::vec3 gravity = kStandardGravity;
};

// Fills the scene's water volume with exactly params.particles particles on a cubic lattice whose
// spacing makes the lattice's volume equal to the water's.
Scene build_scene(const SceneParams& params);

// Lattice points of spacing `spacing` inside a ball, clipped to `tank`: what a user pours in.
std::vector<glm::vec3> ball_of_particles(glm::vec3 centre, float radius, float spacing,
                                         const Box& tank);

}  // namespace fluidcast::sim

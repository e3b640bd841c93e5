// The inputs a user changes while the fluid runs, for both solvers on both backends: refused when
// bad (and then nothing changes), survived when extreme, and deterministic on the CPU.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "solver_test_support.h"
#include "substeps.h"

namespace fluidcast::sim {
namespace {

using testing::make_solver;
using testing::run_for;

using testing::Backend;

struct Case {
  SolverKind kind;
  Backend backend;
};

class SolverInputs : public ::testing::TestWithParam<Case> {
 protected:
  // Lavapipe runs the GPU solvers some hundred times slower than the CPU ones run here: the GPU
  // cases use a quarter of the particles, enough for every situation the tests make.
  std::size_t n_ = GetParam().backend == Backend::gpu ? 250 : 1000;

  std::unique_ptr<Solver> small(SolverParams params = {}) {
    return make_solver(GetParam().kind, SceneKind::dam_break, static_cast<int>(n_), params,
                       GetParam().backend);
  }
};

template <class F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST_P(SolverInputs, BadGravityIsRefusedAndChangesNothing) {
  auto s = small();
  EXPECT_NE(error_of([&] { s->set_gravity({0, NAN, 0}); }).find("gravity"), std::string::npos);
  EXPECT_NE(error_of([&] { s->set_gravity({0, -3000, 0}); }).find("exceeds"), std::string::npos);
  EXPECT_EQ(s->gravity(), kStandardGravity);
}

// A fluid built while the tank is tilted (a session rebuilt under a phone held sideways) starts
// under that gravity, and PBF's substep rule starts from its weight along it: the dam break's
// column, lying on its side, is half as deep, and the tolerance of 10⁻⁴ gives it fewer substeps.
TEST_P(SolverInputs, AFluidBuiltUnderATiltStartsUnderIt) {
  SolverParams params;
  params.pbf_density_tolerance = 1e-4f;
  SceneParams upright;
  upright.particles = static_cast<int>(n_);
  Scene sideways = build_scene(upright);
  sideways.gravity = {-9.81f, 0.0f, 0.0f};
  auto tilted = make_solver(GetParam().kind, sideways, params, GetParam().backend);
  EXPECT_EQ(tilted->gravity(), sideways.gravity);
  if (GetParam().kind == SolverKind::pbf) {
    const float step = params.time_step;
    EXPECT_LT(tilted->substeps_for(step), small(params)->substeps_for(step));
  }
  // The scene's gravity is where a fluid starts; a reset keeps the gravity in force.
  tilted->set_gravity({0.0f, 0.0f, 9.81f});
  tilted->reset();
  EXPECT_EQ(tilted->gravity(), glm::vec3(0.0f, 0.0f, 9.81f));

  Scene falling_fast = sideways;
  falling_fast.gravity = {0.0f, -3000.0f, 0.0f};
  EXPECT_NE(error_of([&] {
              make_solver(GetParam().kind, falling_fast, params, GetParam().backend);
            }).find("scene: gravity"),
            std::string::npos);
}

// A film of water 40 × 40 particles and two layers deep (a spacing of 0.05 m) built on a
// 2 × 2 m floor, without gravity, after one step.
struct Film {
  ParticleSet after;
  FluidConstants fluid;
};
Film film_after_a_step(const Case& c) {
  SceneParams film;
  film.kind = SceneKind::pool;
  film.particles = 3200;
  film.tank_length = film.depth = 2.0f;
  film.pool_height = 0.1f;
  Scene scene = build_scene(film);
  scene.gravity = glm::vec3(0.0f);
  auto s = make_solver(c.kind, scene, {}, c.backend);
  s->step();
  s->synchronize();
  return {s->snapshot(), s->fluid()};
}

// Water built against a wall is at rest there: the walls' fluid begins where a lattice's layer
// half a spacing off a wall reads ρ0 (FluidConstants::wall_offset). The film's floor layer, away
// from the side walls, does not rise. With the walls' fluid at the wall plane it read 2.6 % over
// ρ0 and was pushed up at once: after one step PBF's layer rose at 3.3 mm/s and SPH's at 0.5 m/s;
// now 0.67 mm/s (PBF's artificial pressure draws the two layers together) and 0.04 mm/s, on both
// backends.
TEST_P(SolverInputs, WaterBuiltAgainstAWallStaysThere) {
  const auto [after, fluid] = film_after_a_step(GetParam());
  float fastest_rise = 0.0f;
  std::size_t watched = 0;
  for (std::size_t i = 0; i < after.size(); ++i) {
    const glm::vec3 p = after.position[i];
    const bool interior = std::min({p.x, p.z, 2.0f - p.x, 2.0f - p.z}) > 5.0f * fluid.kernel_radius;
    if (!interior || p.y > fluid.spacing) continue;
    ++watched;
    fastest_rise = std::max(fastest_rise, after.velocity[i].y);
  }
  ASSERT_GT(watched, 100u);
  EXPECT_LT(fastest_rise, 1e-3f) << "m/s, the floor's layer of " << watched << " particles";
}

// ... and along the tank's edges and in its corners, where the walls' half-spaces overlap
// (Kernels::walls): the film's floor layer next to the side walls does not move off any wall it
// lies against. With the half-spaces summed, a lattice's edge site read 3.0 % over ρ0 and its
// corner site 8.8 %: after one step the layer moved off its walls at 0.34 m/s in PBF and 1.4 m/s
// in SPH; now 0.62 mm/s and not at all, on both backends.
TEST_P(SolverInputs, WaterBuiltIntoATanksEdgesStaysThere) {
  const auto [after, fluid] = film_after_a_step(GetParam());
  float fastest = 0.0f;  // off a wall the particle lies against
  std::size_t watched = 0;
  for (std::size_t i = 0; i < after.size(); ++i) {
    const glm::vec3 p = after.position[i], v = after.velocity[i];
    const bool at_a_side = std::min({p.x, p.z, 2.0f - p.x, 2.0f - p.z}) < fluid.spacing;
    if (!at_a_side || p.y > fluid.spacing) continue;
    ++watched;
    float off = v.y;
    if (p.x < fluid.spacing) off = std::max(off, v.x);
    if (2.0f - p.x < fluid.spacing) off = std::max(off, -v.x);
    if (p.z < fluid.spacing) off = std::max(off, v.z);
    if (2.0f - p.z < fluid.spacing) off = std::max(off, -v.z);
    fastest = std::max(fastest, off);
  }
  ASSERT_EQ(watched, 4u * 39u);
  EXPECT_LT(fastest, 1e-3f) << "m/s, the floor's layer along the side walls";
}

// PBF's substep rule counts particles closing on a wall, measured on both backends (the GPU's in
// its last pass of each substep). The column, at rest 0.2 m off its wall and loaded without
// gravity (nothing closes on a wall yet), falls sideways toward the wall at 2000 m/s²: after a
// step it has not reached it and closes on it at the speed limit, and the next step takes at
// least what the walls' bound asks for the speeds the step left, more than the travel bound. The
// column thrown away from its wall at 20 m/s, the far wall out of reach, takes the travel bound's.
TEST_P(SolverInputs, AFluidThrownAtAWallTakesTheSubstepsTheWallAsks) {
  if (GetParam().kind != SolverKind::pbf) GTEST_SKIP() << "SPH's substeps follow its own bounds";
  const SolverParams params;
  const float step = params.time_step;
  for (const bool toward : {true, false}) {
    auto s = small();
    s->set_gravity({0.0f, 0.0f, 0.0f});
    std::vector<glm::vec3> positions = s->scene().particles.position;
    if (toward)
      for (glm::vec3& p : positions) p.x += 0.2f;
    const glm::vec3 velocity = toward ? glm::vec3(0.0f) : glm::vec3(20.0f, 0.0f, 0.0f);
    s->replace_particles(positions, std::vector<glm::vec3>(positions.size(), velocity));
    if (toward) s->set_gravity({-2000.0f, 0.0f, 0.0f});
    s->step();
    s->synchronize();
    const ParticleSet after = s->snapshot();
    float fastest = 0.0f, nearest = std::numeric_limits<float>::infinity();
    for (const glm::vec3& v : after.velocity) fastest = std::max(fastest, glm::length(v));
    for (const glm::vec3& p : after.position) nearest = std::min(nearest, p.x);
    const float approach =
        largest_wall_approach(after.position, after.velocity, s->inner_tank(), step);
    const float g = glm::length(s->gravity());
    const PbfSubsteps rule(params, s->fluid().kernel_radius);
    const int travel_alone = rule.count(step, fastest, 0.0f, 0.0f, g);
    if (toward) {
      ASSERT_GT(nearest, s->inner_tank().min.x) << "the column reached its wall in the first step";
      ASSERT_GT(approach, 0.0f);
      EXPECT_GE(s->substeps_for(step), rule.count(step, fastest, 0.0f, approach, g));
      EXPECT_GT(s->substeps_for(step), travel_alone);
    } else {
      EXPECT_EQ(s->substeps_for(step), travel_alone);
    }
  }
}

TEST_P(SolverInputs, BadCollidersAreRefusedAndChangeNothing) {
  auto s = small();
  const std::vector<Collider> good = {{{0.2f, 0.2f, 0.1f}, 0.05f, {0, 0, 0}}};
  s->set_colliders(good);
  std::vector<Collider> bad = good;
  bad[0].radius = -1;
  EXPECT_NE(error_of([&] { s->set_colliders(bad); }).find("collider 0: radius"), std::string::npos);
  bad = good;
  bad[0].centre.x = INFINITY;
  EXPECT_NE(error_of([&] { s->set_colliders(bad); }).find("centre"), std::string::npos);
  bad = good;
  bad[0].velocity = {2000, 0, 0};
  EXPECT_NE(error_of([&] { s->set_colliders(bad); }).find("velocity"), std::string::npos);
  EXPECT_FALSE(error_of([&] { s->set_colliders(std::vector<Collider>(17, good[0])); }).empty());
  ASSERT_EQ(s->colliders().size(), 1u);
  EXPECT_EQ(s->colliders()[0].radius, 0.05f);
}

TEST_P(SolverInputs, AddRemoveAndReset) {
  auto s = small();
  const float spacing = s->fluid().spacing;
  const auto ball = ball_of_particles({1.0f, 0.4f, 0.15f}, 2.2f * spacing, spacing, s->tank());
  ASSERT_GT(ball.size(), 10u);
  s->add_particles(ball, std::vector<glm::vec3>(ball.size(), glm::vec3(0, -1, 0)));
  EXPECT_EQ(s->particle_count(), n_ + ball.size());
  run_for(*s, 0.05);
  testing::expect_sound(*s, n_ + ball.size());

  const std::size_t removed = s->remove_particles_in_sphere({0.0f, 0.0f, 0.0f}, 0.2f);
  EXPECT_GT(removed, 0u);
  EXPECT_EQ(s->particle_count(), n_ + ball.size() - removed);

  s->reset();
  EXPECT_EQ(s->particle_count(), n_);
  EXPECT_EQ(s->time(), 0.0);
  EXPECT_EQ(s->snapshot().position, s->scene().particles.position);
}

// A fluid loaded from outside (a reset, a snapshot) is not the one the substep rule has watched:
// PBF starts it afresh, from its weight. A tolerance of 10⁻⁴ makes that start several substeps
// (7 on the CPU, 4 on the GPU with fewer particles), and the figures of 0.1 s of flow move the
// bound away from it (3 and 2).
TEST_P(SolverInputs, ALoadedFluidStartsTheSubstepRuleAfresh) {
  if (GetParam().kind != SolverKind::pbf) GTEST_SKIP() << "SPH's substeps follow its state alone";
  SolverParams params;
  params.pbf_density_tolerance = 1e-4f;
  const float step = params.time_step;
  auto s = small(params);
  const int fresh = s->substeps_for(step);
  ASSERT_GT(fresh, 1);
  run_for(*s, 0.1);
  s->synchronize();
  ASSERT_NE(s->substeps_for(step), fresh);
  s->reset();
  EXPECT_EQ(s->substeps_for(step), fresh);

  run_for(*s, 0.1);
  s->synchronize();
  ASSERT_NE(s->substeps_for(step), fresh);
  const ParticleSet& start = s->scene().particles;
  s->replace_particles(start.position, start.velocity);
  EXPECT_EQ(s->substeps_for(step), fresh);
  EXPECT_EQ(s->snapshot().position, start.position);
  EXPECT_EQ(s->snapshot().id, start.id);
}

TEST_P(SolverInputs, ReplacedParticlesAreCheckedAndRefusedWhole) {
  auto s = small();
  run_for(*s, 0.02);
  const ParticleSet before = s->snapshot();
  std::vector<glm::vec3> positions = before.position;
  positions[3] = {1.0f, 5.0f, 0.1f};
  EXPECT_NE(error_of([&] {
              s->replace_particles(positions, before.velocity);
            }).find("replace_particles: position 3"),
            std::string::npos);
  EXPECT_NE(error_of([&] { s->replace_particles(before.position, {}); }).find("velocities"),
            std::string::npos);
  EXPECT_EQ(s->snapshot().position, before.position);
  // A smaller fluid replaces it whole, and the time goes on.
  const double time = s->time();
  const std::vector<glm::vec3> fewer(before.position.begin(), before.position.begin() + 100);
  s->replace_particles(fewer, std::vector<glm::vec3>(fewer.size(), glm::vec3(0)));
  EXPECT_EQ(s->particle_count(), 100u);
  EXPECT_EQ(s->time(), time);
  run_for(*s, 0.02);
  testing::expect_sound(*s, 100);
}

TEST_P(SolverInputs, BadParticlesAreRefusedWhole) {
  auto s = small();
  const std::vector<glm::vec3> inside = {{1.0f, 0.5f, 0.1f}}, outside = {{1.0f, 5.0f, 0.1f}};
  const std::vector<glm::vec3> still = {{0, 0, 0}};
  EXPECT_NE(error_of([&] { s->add_particles(outside, still); }).find("not inside the tank"),
            std::string::npos);
  EXPECT_NE(error_of([&] { s->add_particles(inside, {}); }).find("velocities"), std::string::npos);
  const std::vector<glm::vec3> nan = {{NAN, 0.5f, 0.1f}};
  EXPECT_FALSE(error_of([&] { s->add_particles(nan, still); }).empty());
  EXPECT_FALSE(error_of([&] { s->remove_particles_in_sphere({0, 0, 0}, -1); }).empty());
  EXPECT_EQ(s->particle_count(), n_);
}

TEST_P(SolverInputs, ParticlesUpToTheCapAndNotOneMore) {
  SolverParams params;
  const std::size_t cap = n_ + n_ * 2 / 5;
  params.max_particles = static_cast<int>(cap);
  auto s = small(params);
  std::vector<glm::vec3> more;
  // Drop them in a column right on top of the water: the worst overlap a user can make.
  for (int i = 0; more.size() < cap - n_; ++i) {
    more.push_back({0.05f + 0.01f * (i % 30), 0.3f + 0.002f * (i / 30), 0.15f});
  }
  s->add_particles(more, std::vector<glm::vec3>(more.size(), glm::vec3(0)));
  const std::vector<glm::vec3> one = {{1.0f, 0.5f, 0.1f}};
  EXPECT_NE(
      error_of([&] { s->add_particles(one, one); }).find("the limit is " + std::to_string(cap)),
      std::string::npos);
  run_for(*s, 0.1);
  testing::expect_sound(*s, cap);
}

// The solver's state, every particle within kMaxSpeed, handed back to it; returns that state.
ParticleSet expect_taken_back(Solver& solver) {
  const ParticleSet state = solver.snapshot();
  float fastest = 0.0f;
  for (const glm::vec3& v : state.velocity) fastest = std::max(fastest, glm::length(v));
  EXPECT_TRUE(within_limit(glm::vec3(fastest, 0.0f, 0.0f), kMaxSpeed)) << fastest << " m/s";
  EXPECT_NO_THROW(solver.replace_particles(state.position, state.velocity));
  return state;
}

// A state a solver hands out is one it takes back, whatever the steps were: the reconnecting
// client's and the snapshot's path. Particles given inside a wall's particle radius and a finger
// set down over the water are put out within one sliver of a substep, and v = Δx / Δt threw them
// at 1.6–1.9 × 10⁵ m/s (PBF), past the kMaxSpeed that replace_particles asks of a state (found by
// solver_inputs_fuzz); the solvers hold every particle to it.
TEST_P(SolverInputs, AStateHandedOutAfterASliverOfAStepIsTakenBack) {
  auto s = small();
  const Box inner = s->inner_tank();
  std::vector<glm::vec3> at_walls;
  for (int i = 0; i < 8; ++i) {
    const float y = 0.1f + 0.05f * static_cast<float>(i);
    at_walls.push_back({s->tank().min.x + 1e-4f, y, 0.15f});
    at_walls.push_back({inner.max.x + 0.5f * (s->tank().max.x - inner.max.x), y, 0.15f});
  }
  s->add_particles(at_walls, std::vector<glm::vec3>(at_walls.size(), glm::vec3(0.0f)));
  const Collider finger{{0.2f, 0.3f, 0.15f}, 0.2f, {0.0f, 0.0f, 0.0f}};
  s->set_colliders(std::span(&finger, 1));
  s->step(1e-6f, 1);
  const ParticleSet state = expect_taken_back(*s);
  run_for(*s, 0.1);
  testing::expect_sound(*s, state.size());
}

// A particle at the speed limit that a finger at the speed limit hits from the side leaves with
// the finger's speed into it and its own across it: 1372 m/s for SPH, which sets the approach to
// the finger's, unless held after the colliders as well.
TEST_P(SolverInputs, AFingerAtTheSpeedLimitKeepsWhatItHitsWithinIt) {
  auto s = small();
  std::vector<glm::vec3> positions, velocities;
  for (int i = 0; i < 8; ++i) {
    positions.push_back({0.8f, 0.2f + 0.05f * static_cast<float>(i), 0.15f});
    velocities.push_back({0.0f, 0.0f, kMaxSpeed});
  }
  s->add_particles(positions, velocities);
  const Collider finger{{0.75f, 0.35f, 0.15f}, 0.2f, {kMaxSpeed, 0.0f, 0.0f}};
  s->set_colliders(std::span(&finger, 1));
  s->step(1e-5f, 1);
  expect_taken_back(*s);
}

TEST_P(SolverInputs, ColliderAtOneHundredMetresPerSecond) {
  auto s = small();
  for (int k = 0; k < 30; ++k) {
    // Sweeps back and forth through the water column, 0.83 m a step.
    const float x = (k % 2 == 0) ? 0.05f : 1.55f;
    const Collider finger{{x, 0.15f, 0.15f}, 0.1f, {(k % 2 == 0 ? -100.0f : 100.0f), 0, 0}};
    s->set_colliders(std::span(&finger, 1));
    s->step();
  }
  testing::expect_sound(*s, n_);
}

TEST_P(SolverInputs, GravityOfOneHundredG) {
  auto s = small();
  s->set_gravity({0, -981.0f, 0});
  run_for(*s, 0.2);
  testing::expect_sound(*s, n_);
  s->set_gravity({981.0f, 0, 0});
  run_for(*s, 0.2);
  testing::expect_sound(*s, n_);
}

// Every input at the edge of its accepted range at once: the longest step, the strongest gravity
// turned about, the fastest finger (its substeps capped by max_substeps, so it jumps): nothing
// becomes NaN and nothing leaves the tank.
TEST_P(SolverInputs, EveryInputAtItsLimit) {
  SolverParams params;
  params.time_step = 0.05f;
  auto s = small(params);
  for (int k = 0; k < 8; ++k) {
    const float angle = 0.8f * static_cast<float>(k);
    s->set_gravity({kMaxGravity * std::sin(angle), -kMaxGravity * std::cos(angle), 0.0f});
    const float direction = k % 2 == 0 ? 1.0f : -1.0f;
    const Collider finger{{0.8f, 0.3f, 0.15f}, 0.2f, {direction * kMaxSpeed, 0.0f, 0.0f}};
    s->set_colliders(std::span(&finger, 1));
    s->step();
    SCOPED_TRACE("step " + std::to_string(k));
    testing::expect_sound(*s, n_);
  }
}

// The kinetic energy a fluid can have gained from gravity: its mass falling the tank's diagonal
// `times` over (each turn of gravity can release that much again).
double energy_gravity_can_give(const Solver& s, double times) {
  return times * static_cast<double>(s.particle_count()) * s.fluid().particle_mass *
         glm::length(s.gravity()) * glm::length(s.tank().size());
}

// A finger dragged back and forth through the column at 5 m/s, 0.04 m a step, clear of the walls
// (pressed against a wall, a finger has no room to push particles into): no particle ends a step
// inside it (none tunnels through), none leaves the tank, and the fluid holds no more energy
// than the finger and gravity could have given it.
TEST_P(SolverInputs, FingerDraggedFastLeavesNoParticleInsideIt) {
  auto s = small();
  const float radius = 0.08f;
  // What a finger moving at v can give each particle it meets: at most (2v)²/2 per unit mass.
  const double finger_work_bound =
      0.5 * static_cast<double>(n_) * small()->fluid().particle_mass * 4.0 * 25.0;
  for (int k = 0; k < 60; ++k) {
    const float speed = (k / 10) % 2 == 0 ? 5.0f : -5.0f;
    const glm::vec3 centre = k == 0 ? glm::vec3(0.12f, 0.2f, 0.15f) : s->colliders()[0].centre;
    const Collider finger{centre, radius, {speed, 0.0f, 0.0f}};
    s->set_colliders(std::span(&finger, 1));
    s->step();
    const ParticleSet p = s->snapshot();
    std::size_t inside = 0;
    for (const glm::vec3& x : p.position) {
      inside += glm::length(x - s->colliders()[0].centre) < radius ? 1 : 0;
    }
    ASSERT_EQ(inside, 0u) << "after step " << k;
  }
  testing::expect_sound(*s, n_);
  EXPECT_LT(testing::stats(*s).kinetic_energy,
            finger_work_bound + energy_gravity_can_give(*s, 1.0));
}

// A phone turned fully round, a quarter turn every 0.25 s, then held: the fluid stays in the tank,
// its energy within what gravity gave, and (PBF) its compression back within a few per cent.
TEST_P(SolverInputs, FullTiltsKeepTheFluidSoundAndItsEnergyBounded) {
  auto s = small();
  const float g = 9.81f;
  for (const glm::vec3 gravity :
       {glm::vec3(g, 0, 0), glm::vec3(0, g, 0), glm::vec3(-g, 0, 0), glm::vec3(0, -g, 0)}) {
    s->set_gravity(gravity);
    run_for(*s, 0.25);
    testing::expect_sound(*s, n_);
    EXPECT_LT(testing::stats(*s).kinetic_energy, energy_gravity_can_give(*s, 4.0));
  }
  run_for(*s, 0.5);
  const FluidStatistics settled = testing::stats(*s);
  EXPECT_LT(settled.kinetic_energy, energy_gravity_can_give(*s, 1.0));
  if (GetParam().kind == SolverKind::pbf) {
    EXPECT_LT(settled.avg_density_error, 0.02);
  }
}

// A finger flicked at 30 m/s across the top of the tank, well clear of a pool at rest, cuts its
// steps several times finer (the finger must not jump over particles); the pool stays at rest,
// stepped whole or in slow motion (one substep a call, as a frame loop out of time runs it). The
// iterations stiffen a fluid as 1/Δt²: made as much stiffer, the pool would release the
// compression its longer substeps held, as velocity (PbfSubsteps::stiffness_substep). Measured:
// whole steps 0.0141 and 0.0187 m/s rms (CPU and lavapipe, the pool at 0.014 m/s at rest), 0.43
// and 0.61 m/s when every cut stiffened the fluid, 0.43 and 0.61 in slow motion when its stiffness
// followed the short step's own substeps; 0.06 on lavapipe with λ taken in full from 2
// tolerances rather than 3 (PbfSubsteps::kPressedFrom).
TEST_P(SolverInputs, AFingerFlickedAboveAPoolAtRestLeavesItAtRest) {
  if (GetParam().kind != SolverKind::pbf) GTEST_SKIP() << "SPH's stiffness is its own";
  SceneParams scene;
  scene.kind = SceneKind::pool;
  scene.particles = static_cast<int>(n_);
  scene.tank_length = 0.4f;
  scene.depth = 0.1f;
  const Collider finger{{0.2f, 0.8f, 0.05f}, 0.05f, {30.0f, 0.0f, 0.0f}};
  for (const bool slow_motion : {false, true}) {
    SCOPED_TRACE(slow_motion ? "in slow motion" : "whole steps");
    auto pool = make_solver(SolverKind::pbf, scene, {}, GetParam().backend);
    const float step = pool->params().time_step;
    int resting_substeps = pool->params().max_substeps;
    for (int k = 0; k < 240; ++k) {
      const int substeps = pool->step();
      if (k >= 240 - 16) resting_substeps = std::min(resting_substeps, substeps);
    }
    const FluidStatistics rest = testing::stats(*pool);
    int flicked_substeps = 0;
    double most_energy = rest.kinetic_energy;
    for (int k = 0; k < 60; ++k) {
      pool->set_colliders(std::span(&finger, 1));  // back where it started: it stays above
      const int substeps = pool->substeps_for(step);
      flicked_substeps = std::max(flicked_substeps, substeps);
      if (slow_motion) {
        for (int s = 0; s < substeps; ++s) pool->step(step / static_cast<float>(substeps), 1);
      } else {
        pool->step(step, substeps);
      }
      if (k % 4 == 3) most_energy = std::max(most_energy, testing::stats(*pool).kinetic_energy);
    }
    testing::expect_sound(*pool, n_);
    const double mass = static_cast<double>(n_) * pool->fluid().particle_mass;
    const double rms_speed_at_rest = std::sqrt(2.0 * rest.kinetic_energy / mass);
    const double most_rms_speed = std::sqrt(2.0 * most_energy / mass);
    std::printf(
        "pool at rest: %d substeps a step, rms speed %.4f m/s, largest density error %.4f; a "
        "finger flicked above%s: %d substeps, rms speed up to %.4f m/s\n",
        resting_substeps, rms_speed_at_rest, rest.max_density_error,
        slow_motion ? " in slow motion" : "", flicked_substeps, most_rms_speed);
    EXPECT_GE(flicked_substeps, 2 * resting_substeps);
    EXPECT_LT(most_rms_speed, 0.05);
  }
}

// Each limit of the solver's inputs (the same code on either backend) passes at its value and
// refuses the next, in words that name what was wrong; what is refused changes nothing.
TEST(CpuSolverInputs, EachInputPassesAtItsLimitAndNotPast) {
  SolverParams params;
  params.max_substeps = 3;
  auto s = make_solver(SolverKind::pbf, SceneKind::dam_break, 1000, params);
  const float dt = params.time_step;
  EXPECT_NO_THROW(s->step(dt, 3));
  EXPECT_NE(error_of([&] { s->step(dt, 4); }).find("substeps are not in [1, 3]"),
            std::string::npos);
  EXPECT_NE(error_of([&] { s->step(1.01f * dt, 1); }).find("the time step"), std::string::npos);
  // A denormal step made PBF's velocities inf·0 = NaN.
  EXPECT_NO_THROW(s->step(kShortestSubstep, 1));
  EXPECT_NE(error_of([&] { s->step(1e-40f, 1); }).find("is less than 1e-09 s a substep"),
            std::string::npos);
  EXPECT_NE(error_of([&] { s->step(2.5e-9f, 3); }).find("in 3 substeps is less than"),
            std::string::npos);
  testing::expect_sound(*s, 1000);
  EXPECT_NE(error_of([&] {
              s->set_gravity({0, 0, std::numeric_limits<float>::infinity()});
            }).find("must be finite"),
            std::string::npos);
  EXPECT_EQ(s->gravity(), kStandardGravity);

  Collider finger{{0.8f, 0.5f, 0.15f}, kMaxColliderRadius, {0, 0, 0}};
  EXPECT_NO_THROW(s->set_colliders({&finger, 1}));
  finger.radius = 1.01f * kMaxColliderRadius;
  EXPECT_NE(error_of([&] {
              s->set_colliders({&finger, 1});
            }).find("collider 0: radius"),
            std::string::npos);

  const std::vector<glm::vec3> at = {{1.2f, 0.5f, 0.15f}};
  EXPECT_NE(error_of([&] {
              s->add_particles(at, std::vector<glm::vec3>{{1.01f * kMaxSpeed, 0, 0}});
            }).find("velocity 0"),
            std::string::npos);
  EXPECT_EQ(s->particle_count(), 1000u);
  EXPECT_NO_THROW(s->add_particles(at, std::vector<glm::vec3>{{kMaxSpeed, 0, 0}}));
  s->add_particles(at, std::vector<glm::vec3>{{0, 0, 0}});
  std::vector<std::uint32_t> ids = s->snapshot().id;  // each added particle a new id
  std::sort(ids.begin(), ids.end());
  EXPECT_EQ(std::adjacent_find(ids.begin(), ids.end()), ids.end());

  EXPECT_NE(error_of([&] {
              s->remove_particles_in_sphere({0, 0, 0}, std::numeric_limits<float>::infinity());
            }).find("radius must be finite"),
            std::string::npos);
  EXPECT_EQ(s->remove_particles_in_sphere({0.05f, 0.05f, 0.05f}, 0.0f), 0u);
  EXPECT_EQ(s->particle_count(), 1002u);
  EXPECT_THROW(s->set_time(std::numeric_limits<double>::infinity()), std::invalid_argument);
  EXPECT_NO_THROW(s->set_time(0.0));
}

// CPU only: on the GPU the order within a grid cell follows atomics, so sums differ in their
// last bits from run to run.
TEST(CpuSolverInputs, DeterministicForAThreadCount) {
  for (const SolverKind kind : {SolverKind::pbf, SolverKind::sph}) {
    SCOPED_TRACE(to_string(kind));
    auto run = [&](int threads) {
      SolverParams params;
      params.threads = threads;
      auto s = make_solver(kind, SceneKind::dam_break, 1500, params);
      const Collider finger{{0.3f, 0.2f, 0.15f}, 0.06f, {1, 0, 0}};
      s->set_colliders(std::span(&finger, 1));
      run_for(*s, 0.3);
      return s->snapshot();
    };
    const ParticleSet a = run(2), b = run(2);
    EXPECT_EQ(a.position, b.position);
    EXPECT_EQ(a.velocity, b.velocity);
    EXPECT_EQ(a.id, b.id);
    // Each particle is computed from the same inputs in the same order whatever the split, so the
    // thread count does not change the result either.
    EXPECT_EQ(run(1).position, a.position);
  }
}

// Every scene as built, and fluids in motion (a dam break's front hitting the wall, a drop
// splashing), are plausible states; particles clumped at a point are not, and the refusal names
// where.
TEST(CheckDensity, FluidStatesPassAndClumpsAreRefused) {
  for (const SceneKind scene :
       {SceneKind::dam_break, SceneKind::double_dam_break, SceneKind::drop, SceneKind::pool}) {
    for (const SolverKind kind : {SolverKind::pbf, SolverKind::sph}) {
      SCOPED_TRACE(std::string(to_string(scene)) + ", " + std::string(to_string(kind)));
      auto s = make_solver(kind, scene, 1000);
      EXPECT_NO_THROW(check_density(s->snapshot().position, s->fluid()));
      for (int k = 0; k < 6; ++k) {
        run_for(*s, 0.1);
        EXPECT_NO_THROW(check_density(s->snapshot().position, s->fluid())) << s->time() << " s";
      }
    }
  }
  auto s = make_solver(SolverKind::pbf, SceneKind::dam_break, 2000);
  std::vector<glm::vec3> clump = s->snapshot().position;
  for (std::size_t k = 0; k < 400; ++k) clump[k] = {0.8f, 0.3f, 0.15f};
  const std::string error = error_of([&] { check_density(clump, s->fluid()); });
  EXPECT_NE(error.find("times the fluid's rest density"), std::string::npos) << error;
}

// The bound is twice the particles a cube of two kernel radii holds at rest: that many at one
// point pass, one more does not.
TEST(CheckDensity, TwiceRestDensityPassesAndNotOneParticleMore) {
  auto s = make_solver(SolverKind::pbf, SceneKind::dam_break, 1000);
  const float side = 2.0f * s->fluid().kernel_radius;
  const auto most =
      static_cast<std::size_t>(kMaxDensityRatio * std::pow(side / s->fluid().spacing, 3.0f));
  std::vector<glm::vec3> clump(most, glm::vec3(0.8f, 0.3f, 0.15f));
  EXPECT_NO_THROW(check_density(clump, s->fluid()));
  clump.push_back(clump.back());
  EXPECT_THROW(check_density(clump, s->fluid()), std::invalid_argument);
}

// Positions a caller has not checked against a tank: far apart, or not numbers, are refused in
// words, not computed with (coverage-guided fuzzing found the cube index overflowing an int).
TEST(CheckDensity, PositionsFarApartOrNotFiniteAreRefused) {
  auto s = make_solver(SolverKind::pbf, SceneKind::dam_break, 1000);
  std::vector<glm::vec3> positions = s->snapshot().position;
  positions[7] = {-3.2e8f, 0.5f, 0.5f};
  EXPECT_NE(error_of([&] { check_density(positions, s->fluid()); }).find("spread over more than"),
            std::string::npos);
  positions[7] = {0.5f, std::numeric_limits<float>::infinity(), 0.5f};
  EXPECT_NE(error_of([&] { check_density(positions, s->fluid()); }).find("not finite"),
            std::string::npos);
  positions[7] = {1e5f, 0.5f, 0.5f};  // far, but within reach of the cubes: counted, and fine
  EXPECT_NO_THROW(check_density(positions, s->fluid()));
}

INSTANTIATE_TEST_SUITE_P(BothSolversBothBackends, SolverInputs,
                         ::testing::Values(Case{SolverKind::pbf, Backend::cpu},
                                           Case{SolverKind::sph, Backend::cpu},
                                           Case{SolverKind::pbf, Backend::gpu},
                                           Case{SolverKind::sph, Backend::gpu}),
                         [](const ::testing::TestParamInfo<Case>& param) {
                           return std::string(to_string(param.param.kind)) +
                                  (param.param.backend == Backend::gpu ? "_gpu" : "_cpu");
                         });

}  // namespace
}  // namespace fluidcast::sim

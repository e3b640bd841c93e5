// A small fluid's tunables and a run of what a user does to it, read from any bytes — tilts
// (gravity), fingers (colliders, and drags as the server moves them), steps whole and in slow
// motion, particles added and removed, resets, reloads — within the inputs' limits and past them.
// An input past a limit must be refused with std::invalid_argument and leave the fluid, gravity,
// fingers and clock as they were; whatever is taken, the fluid must stay finite and inside the
// tank, keep its count, and be a state the solver takes back. Not checked: the server's density
// check of a snapshot, which a fluid may fail at tunables and inputs that are the user's to choose
// (one iteration under 122 g on capped substeps, a 10 m finger, a pour onto one point).
// solver_inputs_fuzz runs it on the CPU solvers, and gpu_solver_inputs_test its corpus on the
// GPU's.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <limits>
#include <memory>
#include <span>
#include <stdexcept>
#include <type_traits>
#include <variant>
#include <vector>

#include "fluidcast/sim/finger_collider.h"
#include "fluidcast/sim/scene.h"
#include "fluidcast/sim/solver.h"
#include "fluidcast/sim/solver_params.h"
#include "fuzz_bytes.h"

namespace fluidcast::sim::fuzzing {

using fluidcast::fuzzing::Bytes;
using fluidcast::fuzzing::defect;
using fluidcast::fuzzing::Defect;

using SolverMaker = std::function<std::unique_ptr<Solver>(SolverKind, Scene, const SolverParams&)>;

// Every particle finite, inside the tank, and as many as expected. After a step, inside the box
// particle centres keep to (the tank shrunk by a particle radius); a particle added or a scene
// built may lie nearer a wall until then.
inline void expect_sound(const Solver& solver, std::size_t count, bool stepped) {
  const ParticleSet particles = solver.snapshot();
  if (particles.size() != count) defect("the fluid's particle count changed on its own");
  const Box inner = stepped ? solver.inner_tank() : solver.tank();
  for (std::size_t i = 0; i < particles.size(); ++i) {
    const glm::vec3 p = particles.position[i], v = particles.velocity[i];
    for (int axis = 0; axis < 3; ++axis) {
      if (!std::isfinite(p[axis]) || !std::isfinite(v[axis])) defect("a particle is not finite");
      if (p[axis] < inner.min[axis] || p[axis] > inner.max[axis]) {
        std::fprintf(stderr, "particle %zu of %zu: %g along axis %d, the tank's inside [%g, %g]\n",
                     i, particles.size(), p[axis], axis, inner.min[axis], inner.max[axis]);
        defect("a particle left the tank");
      }
    }
  }
}

inline bool same(const ParticleSet& a, const ParticleSet& b) {
  return a.position == b.position && a.velocity == b.velocity && a.id == b.id;
}

inline bool same(std::span<const Collider> a, std::span<const Collider> b) {
  return std::equal(
      a.begin(), a.end(), b.begin(), b.end(), [](const Collider& x, const Collider& y) {
        return x.centre == y.centre && x.radius == y.radius && x.velocity == y.velocity;
      });
}

// Runs `input` (an input to the solver that throws std::invalid_argument to refuse); a refused
// one must leave the fluid, its gravity and its colliders as they were.
template <class Input>
void refused_changes_nothing(Solver& solver, Input input) {
  const ParticleSet before = solver.snapshot();
  const glm::vec3 gravity = solver.gravity();
  const std::vector<Collider> colliders = solver.colliders();
  const double time = solver.time();
  try {
    input();
  } catch (const std::invalid_argument&) {
    if (!same(before, solver.snapshot()) || gravity != solver.gravity() ||
        !same(colliders, solver.colliders()) || time != solver.time())
      defect("a refused input changed the fluid");
  }
}

// Sets about half of `owner`'s tunables anywhere in their declared ranges (a log scale where a
// range spans more than two decades), the others left at their defaults.
template <class Owner>
void set_some(Bytes& in, Owner& owner, const std::vector<ParamSpec<Owner>>& specs) {
  for (const ParamSpec<Owner>& spec : specs) {
    if (in.byte() % 2 == 0) continue;
    // From 0: a log scale from a ten-thousandth of the range, and now and then 0 itself (a
    // viscosity of [0, 100] Pa·s defaults to 0.05).
    double value;
    if (spec.min > 0.0 && spec.max > 100.0 * spec.min)
      value = in.scaled(spec.min, spec.max);
    else if (spec.min == 0.0)
      value = in.byte() % 8 == 0 ? 0.0 : in.scaled(1e-4 * spec.max, spec.max);
    else
      value = in.between(spec.min, spec.max);
    std::visit(
        [&](auto field) {
          owner.*field = static_cast<std::remove_reference_t<decltype(owner.*field)>>(value);
        },
        spec.member);
  }
}

// The solver the input's first bytes describe, from `make`; none where they describe a scene
// that does not fit its tank.
inline std::unique_ptr<Solver> build(Bytes& in, const SolverMaker& make) {
  SolverParams params;
  set_some(in, params, solver_param_specs());
  // What a run can afford: a few hundred particles, a few iterations and substeps, one thread (the
  // same input then runs the same way every time).
  params.threads = 1;
  params.iterations = std::min(params.iterations, 8);
  params.max_substeps = std::min(params.max_substeps, 64);
  params.max_particles = 64 + in.up_to(255) * 2;
  SceneParams scene;
  set_some(in, scene, scene_param_specs());
  scene.kind = static_cast<SceneKind>(in.up_to(3));
  scene.particles = 30 + in.up_to(255);
  // The grid covers the tank, its cells half a kernel radius: a wide tank with few particles pays
  // for millions of cells a substep (9 × 9 × 0.01 m, 30 particles: 7 M), a cost the user chose but
  // one that leaves a run no time for anything else.
  scene.tank_length = std::min(scene.tank_length, 2.0f);
  scene.tank_height = std::min(scene.tank_height, 2.0f);
  scene.depth = std::min(scene.depth, 2.0f);
  const SolverKind kind = in.byte() % 4 == 0 ? SolverKind::sph : SolverKind::pbf;
  try {
    validate(scene);  // a geometry that does not fit its tank is the CLI's to refuse
    return make(kind, build_scene(scene), params);
  } catch (const ParamError&) {
    return nullptr;
  }
}

// Runs the input on the solver it describes; throws Defect where a promise was broken.
inline void run_solver_inputs(const std::uint8_t* data, std::size_t size, const SolverMaker& make) {
  Bytes in(data, size);
  const std::unique_ptr<Solver> solver = build(in, make);
  if (!solver) return;
  std::size_t count = solver->particle_count();
  expect_sound(*solver, count, false);
  const float step = solver->params().time_step;
  for (int action = 0; action < 24 && !in.done(); ++action) {
    bool stepped = false;
    switch (in.byte() % 10) {
      case 0:
      case 1:
        solver->step();
        stepped = true;
        break;
      case 2: {  // a shorter step, down to slivers, its substeps by the solver's own rule
        const float seconds = step * std::max(in.unit(), 1e-3f);
        solver->step(seconds, solver->substeps_for(seconds));
        stepped = true;
        break;
      }
      case 3: {  // a step of any length and substeps: most are refused
        const float seconds = in.around(step);
        const int substeps = in.up_to(solver->params().max_substeps + 1);
        refused_changes_nothing(*solver, [&] {
          solver->step(seconds, substeps);
          stepped = true;
        });
        break;
      }
      case 4: {  // a tilt, a shake
        const glm::vec3 direction = in.direction();
        const glm::vec3 gravity = direction * in.around(kMaxGravity);
        refused_changes_nothing(*solver, [&] { solver->set_gravity(gravity); });
        break;
      }
      case 5: {  // fingers
        std::vector<Collider> fingers(static_cast<std::size_t>(in.up_to(3)));
        if (in.byte() % 8 == 0) fingers.resize(kMaxColliders + 1);
        for (Collider& finger : fingers) {
          finger.centre = in.point_around(solver->tank());
          finger.radius = in.byte() % 8 == 0 ? in.around(kMaxColliderRadius) : in.scaled(1e-3, 0.3);
          const glm::vec3 direction = in.direction();
          finger.velocity = direction * in.around(kMaxSpeed);
        }
        refused_changes_nothing(*solver, [&] { solver->set_colliders(fingers); });
        break;
      }
      case 6: {  // particles poured in, some outside the tank or too fast
        std::vector<glm::vec3> positions(static_cast<std::size_t>(1 + in.up_to(40)));
        std::vector<glm::vec3> velocities(positions.size());
        for (std::size_t i = 0; i < positions.size(); ++i) {
          positions[i] = in.point_around(solver->inner_tank());
          const glm::vec3 direction = in.direction();
          velocities[i] = direction * in.around(kMaxSpeed);
        }
        refused_changes_nothing(*solver, [&] {
          solver->add_particles(positions, velocities);
          count += positions.size();
        });
        break;
      }
      case 7: {  // a finger's removal, or the fluid reset
        if (in.byte() % 4 == 0) {
          solver->reset();
          count = solver->scene().particles.size();
          break;
        }
        const glm::vec3 centre = in.point_around(solver->tank());
        const float radius = in.scaled(1e-3, 1.0);
        // Those well inside the sphere go, those well outside stay; within rounding of its
        // surface (the solvers' sums may be fused differently), either.
        const ParticleSet before = solver->snapshot();
        const std::size_t removed = solver->remove_particles_in_sphere(centre, radius);
        const ParticleSet after = solver->snapshot();
        std::vector<std::uint32_t> kept(after.id.begin(), after.id.end());
        std::sort(kept.begin(), kept.end());
        for (std::size_t i = 0; i < before.size(); ++i) {
          const float reach = glm::distance(before.position[i], centre) / radius;
          const bool stayed = std::binary_search(kept.begin(), kept.end(), before.id[i]);
          if ((reach < 1.0f - 1e-4f && stayed) || (reach > 1.0f + 1e-4f && !stayed))
            defect("a removal took other particles than those in its sphere");
        }
        if (before.size() - after.size() != removed)
          defect("a removal took other than as many particles as it said");
        count -= removed;
        break;
      }
      case 9: {  // a drag, as the server's fingers follow a hand (FingerCollider): steps of a
                 // tick's seconds, the hand anywhere, the ticks' wall time even or bunched
        const float radius = in.scaled(1e-3, 0.3);
        FingerCollider sphere(in.point_around(solver->tank()));
        for (int tick = 1 + in.up_to(7); tick > 0; --tick) {
          const float seconds = in.byte() % 4 == 0 ? 0.0f : step * std::max(in.unit(), 0.01f);
          const double elapsed = in.byte() % 4 == 0 ? 0.0 : in.scaled(1e-3, 0.5);
          const auto motion = sphere.follow(in.point_around(solver->tank()), seconds, elapsed);
          std::vector<Collider> fingers;
          if (const auto finger = motion.collider(radius)) fingers.push_back(*finger);
          try {
            solver->set_colliders(fingers);
          } catch (const std::invalid_argument& refusal) {
            std::fprintf(stderr, "%s\n", refusal.what());
            defect("the solver refused a finger that FingerCollider moved");
          }
          if (seconds > 0.0f) solver->step(seconds, solver->substeps_for(seconds));
          expect_sound(*solver, count, seconds > 0.0f);
        }
        break;
      }
      case 8: {  // the fluid handed back as a snapshot, as a reconnecting client does
        const ParticleSet state = solver->snapshot();
        try {
          solver->replace_particles(state.position, state.velocity);
        } catch (const std::invalid_argument& refusal) {
          std::fprintf(stderr, "%s\n", refusal.what());
          defect("the fluid's own state was refused as a snapshot");
        }
        break;
      }
    }
    expect_sound(*solver, count, stepped);
  }
}

}  // namespace fluidcast::sim::fuzzing

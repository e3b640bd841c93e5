// The page's local fluid: the project's CPU solvers (PBF, SPH), scenes and colliders, compiled to
// WebAssembly and driven from JavaScript (client/web/local_fluid.js) through these C functions.
// One fluid per module instance. Functions that can fail return nullptr on success and otherwise
// a sentence saying what was wrong, valid until the next call.
#include <emscripten/emscripten.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <exception>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "fluidcast/sim/finger_collider.h"
#include "fluidcast/sim/scene.h"
#include "fluidcast/sim/solver.h"

namespace {

using namespace fluidcast::sim;

// A finger down: where it points and the sphere that follows it (FingerCollider, as the server's
// sessions have it). A lifted one's sphere goes on to where it pointed last, then is gone.
struct Finger {
  FingerCollider sphere;
  glm::vec3 target;
  float radius;
  bool lifted = false;
};

struct LocalFluid {
  std::unique_ptr<Solver> solver;
  ParticleSet shown;  // the newest state, read by JavaScript in place
  std::string error;
  std::vector<std::optional<Finger>> fingers;  // by finger id; empty: none, or lifted and done
  std::vector<float> tank;                     // min x, y, z, max x, y, z
  unsigned threads = 1;  // the solver's, 1 to FLUIDCAST_MAX_THREADS (Web Workers beyond one)
  int iterations = SolverParams{}.iterations;  // PBF's density iterations a substep
};

LocalFluid fluid;

// Runs `body`; a thrown exception becomes the returned sentence.
template <class Body>
const char* attempt(Body&& body) {
  try {
    body();
    return nullptr;
  } catch (const std::exception& e) {
    fluid.error = e.what();
    return fluid.error.c_str();
  }
}

void show() {
  fluid.shown = fluid.solver->snapshot();
  const Box& box = fluid.solver->tank();
  fluid.tank = {box.min.x, box.min.y, box.min.z, box.max.x, box.max.y, box.max.z};
}

// The fluid goes on from `scene` at simulated time `time`; refused whole, the last one stays.
void make(Scene scene, SolverKind kind, glm::vec3 gravity, double time = 0.0) {
  SolverParams params;
  params.threads = static_cast<int>(fluid.threads);
  params.iterations = fluid.iterations;
  scene.gravity = gravity;
  std::unique_ptr<Solver> made = make_cpu_solver(kind, std::move(scene), params);
  made->set_time(time);
  fluid.solver = std::move(made);
  fluid.fingers.clear();
  show();
}

// The fingers become the solver's colliders, whole where their spheres are: the check that they
// are valid (refused as a whole, nothing changes); the next step sets their sizes and motion.
void touch(std::vector<std::optional<Finger>> fingers) {
  std::vector<Collider> down;
  for (const auto& finger : fingers) {
    if (finger) down.push_back({finger->sphere.centre(), finger->radius, glm::vec3(0.0f)});
  }
  fluid.solver->set_colliders(down);
  fluid.fingers = std::move(fingers);
}

// The fingers' spheres for a step of `seconds` (0: none) that comes `wall_seconds` after the
// last call: each moves towards its finger, in simulated time no faster than the hand moved
// (FingerCollider).
void move_fingers(float seconds, double wall_seconds) {
  if (!(std::isfinite(wall_seconds) && wall_seconds >= 0.0)) {
    throw std::invalid_argument("wall_seconds must be finite and at least 0, got " +
                                std::to_string(wall_seconds));
  }
  std::vector<Collider> down;
  for (auto& finger : fluid.fingers) {
    if (!finger) continue;
    const auto motion = finger->sphere.follow(finger->target, seconds, wall_seconds);
    if (const auto collider = motion.collider(finger->radius)) down.push_back(*collider);
    // Lifted and where it pointed: this step's move is the sphere's last.
    if (finger->lifted && finger->sphere.arrived()) finger.reset();
  }
  fluid.solver->set_colliders(down);
}

glm::vec3 gravity_now() { return fluid.solver ? fluid.solver->gravity() : kStandardGravity; }

}  // namespace

extern "C" {

// The threads the next fluid steps with, at most what this build has (1 without pthreads);
// returns the number taken.
EMSCRIPTEN_KEEPALIVE std::uint32_t fluid_use_threads(std::uint32_t threads) {
  fluid.threads = std::clamp<std::uint32_t>(threads, 1, FLUIDCAST_MAX_THREADS);
  return fluid.threads;
}

// PBF's density iterations for the next fluid (the solver checks the range when it is made).
EMSCRIPTEN_KEEPALIVE void fluid_use_iterations(int iterations) { fluid.iterations = iterations; }

EMSCRIPTEN_KEEPALIVE const char* fluid_create(const char* scene, const char* solver,
                                              std::uint32_t particles) {
  return attempt([&] {
    SceneParams params;
    params.kind = parse_scene(scene);
    params.particles = static_cast<int>(particles);
    make(build_scene(params), parse_solver(solver), gravity_now());
  });
}

// Continues from a state (a server's snapshot): the scene's tank with these particles, packed
// x, y, z each, at simulated time `time`, falling under the state's gravity (m/s²).
EMSCRIPTEN_KEEPALIVE const char* fluid_load(const char* scene, const char* solver,
                                            std::uint32_t particles, const float* positions,
                                            const float* velocities, std::uint32_t count,
                                            double time, float gravity_x, float gravity_y,
                                            float gravity_z) {
  return attempt([&] {
    // The scene is spaced for its count: a state of another would be squeezed or stretched.
    if (count != particles) {
      throw std::invalid_argument("load: " + std::to_string(count) + " particles given for a " +
                                  std::to_string(particles) + "-particle scene");
    }
    SceneParams params;
    params.kind = parse_scene(scene);
    params.particles = static_cast<int>(particles);
    Scene state = build_scene(params);
    state.particles = {};
    for (std::uint32_t i = 0; i < count; ++i) {
      state.particles.append({positions[3 * i], positions[3 * i + 1], positions[3 * i + 2]},
                             {velocities[3 * i], velocities[3 * i + 1], velocities[3 * i + 2]}, i);
    }
    check_density(state.particles.position, derive_fluid_constants(state.spacing, SolverParams{}));
    make(std::move(state), parse_solver(solver), {gravity_x, gravity_y, gravity_z}, time);
  });
}

// Advances by `seconds` (at most the solver's step, 1/120 s by default; the page calls it as
// often as a frame needs), in as many substeps as the solver's rule asks, `wall_seconds` after the
// last call to this or fluid_wait (in slow motion, more than `seconds`).
EMSCRIPTEN_KEEPALIVE const char* fluid_step(float seconds, double wall_seconds) {
  return attempt([&] {
    if (!fluid.solver) throw std::invalid_argument("no fluid: call fluid_create first");
    if (!(seconds > 0.0f && std::isfinite(seconds))) {
      throw std::invalid_argument("step: seconds must be positive, got " + std::to_string(seconds));
    }
    const float step = std::min(seconds, fluid.solver->params().time_step);
    move_fingers(step, wall_seconds);
    fluid.solver->step(step, fluid.solver->substeps_for(step));
    show();
  });
}

// `wall_seconds` passed without a step (the page waits for the next, or is paused): the fingers'
// spheres stay where they are, but see how fast the hands went.
EMSCRIPTEN_KEEPALIVE const char* fluid_wait(double wall_seconds) {
  return attempt([&] {
    if (fluid.solver) move_fingers(0.0f, wall_seconds);
  });
}

EMSCRIPTEN_KEEPALIVE float fluid_time_step() {
  return fluid.solver ? fluid.solver->params().time_step : 0.0f;
}
EMSCRIPTEN_KEEPALIVE double fluid_time() { return fluid.solver ? fluid.solver->time() : 0.0; }
EMSCRIPTEN_KEEPALIVE std::uint32_t fluid_count() {
  return static_cast<std::uint32_t>(fluid.shown.size());
}
// x, y, z per particle (m, m/s), valid until the next call that changes the fluid.
EMSCRIPTEN_KEEPALIVE const float* fluid_positions() {
  return reinterpret_cast<const float*>(fluid.shown.position.data());
}
EMSCRIPTEN_KEEPALIVE const float* fluid_velocities() {
  return reinterpret_cast<const float*>(fluid.shown.velocity.data());
}
EMSCRIPTEN_KEEPALIVE const float* fluid_tank() { return fluid.tank.data(); }
// The gravity now (m/s², x, y, z), valid until the next call.
EMSCRIPTEN_KEEPALIVE const float* fluid_gravity() {
  static glm::vec3 gravity;
  gravity = gravity_now();
  return &gravity.x;
}

EMSCRIPTEN_KEEPALIVE float fluid_spacing() {
  return fluid.solver ? fluid.solver->fluid().spacing : 0.0f;
}

EMSCRIPTEN_KEEPALIVE const char* fluid_set_gravity(float x, float y, float z) {
  return attempt([&] {
    if (fluid.solver) fluid.solver->set_gravity({x, y, z});
  });
}

// A finger at (x, y, z) m, held within the tank, its sphere `radius` m; `id` 0 to 15. A new one's
// sphere starts there, one already down moves towards it at the next steps.
EMSCRIPTEN_KEEPALIVE const char* fluid_set_finger(std::uint32_t id, float x, float y, float z,
                                                  float radius) {
  return attempt([&] {
    if (!fluid.solver) return;
    if (id >= kMaxColliders) {
      throw std::invalid_argument("finger: id must be below " + std::to_string(kMaxColliders) +
                                  ", got " + std::to_string(id));
    }
    if (!is_finite(glm::vec3(x, y, z))) {
      throw std::invalid_argument("finger: x, y and z must be finite");
    }
    // Beyond the walls a sphere would push nothing, and come back from afar.
    const glm::vec3 target =
        glm::clamp(glm::vec3(x, y, z), fluid.solver->tank().min, fluid.solver->tank().max);
    std::vector<std::optional<Finger>> fingers = fluid.fingers;
    if (fingers.size() <= id) fingers.resize(id + 1);
    if (fingers[id] && !fingers[id]->lifted) {
      fingers[id]->target = target;
      fingers[id]->radius = radius;
    } else {
      fingers[id] = Finger{FingerCollider(target), target, radius};
    }
    touch(std::move(fingers));
  });
}

EMSCRIPTEN_KEEPALIVE const char* fluid_lift_finger(std::uint32_t id) {
  return attempt([&] {
    if (!fluid.solver || id >= fluid.fingers.size()) return;
    std::vector<std::optional<Finger>> fingers = fluid.fingers;
    if (fingers[id]) fingers[id]->lifted = true;
    touch(std::move(fingers));
  });
}

// The scenes, comma-separated: what the page's menu offers.
EMSCRIPTEN_KEEPALIVE const char* fluid_scene_names() {
  static const std::string names = [] {
    std::string joined;
    for (std::string_view name : scene_names())
      joined += (joined.empty() ? "" : ",") + std::string(name);
    return joined;
  }();
  return names.c_str();
}

// Back to the scene's start at t = 0 — the scene's, also for a fluid continued from a state (whose
// solver would go back to that state).
EMSCRIPTEN_KEEPALIVE const char* fluid_reset() {
  return attempt([&] {
    if (!fluid.solver) return;
    make(build_scene(fluid.solver->scene().params), fluid.solver->kind(), gravity_now());
  });
}

}  // extern "C"

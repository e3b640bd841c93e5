// What every fluid solver offers, CPU or GPU, PBF or SPH: stepping, snapshots, and the inputs a
// user changes while it runs. Inputs are validated here, once, whatever the solver.
#pragma once

#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include "fluidcast/sim/fluid_constants.h"
#include "fluidcast/sim/particles.h"
#include "fluidcast/sim/scene.h"
#include "fluidcast/sim/solver_params.h"

namespace fluidcast::gpu {
class Context;
}

namespace fluidcast::sim {

enum class SolverKind { pbf, sph };

const std::vector<std::string_view>& solver_names();
SolverKind parse_solver(std::string_view name);  // throws ParamError listing the names
std::string_view to_string(SolverKind kind);

// A moving sphere that pushes the fluid: a finger. It moves on at its velocity, through each step,
// until the next set_colliders().
struct Collider {
  glm::vec3 centre{0.0f};    // m
  float radius = 0.05f;      // m
  glm::vec3 velocity{0.0f};  // m/s
};

// Input limits: beyond them an input is refused, never clamped.
inline constexpr float kMaxGravity = 2000.0f;       // m/s², about 200 g
inline constexpr float kMaxSpeed = 1000.0f;         // m/s, colliders and added particles
inline constexpr float kMaxColliderRadius = 10.0f;  // m
inline constexpr std::size_t kMaxColliders = 16;
// A step's slice for each substep is at least this: PBF's velocities are 1/Δt times a distance,
// and a float's 1/Δt overflows below ~3e-39 s (a velocity of inf·0 is NaN).
inline constexpr float kShortestSubstep = 1e-9f;  // s
// A vector's length against one of those limits, allowing for the rounding of a vector scaled to
// the limit exactly (its float length may come out an ulp or two over). NaN is not within.
inline bool within_limit(glm::vec3 v, float limit) {
  return glm::length(v) <= limit * (1.0f + 1e-6f);
}
// The solvers hold every particle to kMaxSpeed too, so that a state a solver hands out is one it
// takes back (replace_particles). Slivers of substeps reached past it: PBF puts a particle given
// inside a wall's particle radius, or inside a collider set down over it, out within a substep,
// and v = Δx / Δt (in 1 µs, at 1.6–1.9 × 10⁵ m/s). So did fingers at the limit: SPH leaves a
// particle that one hits with the finger's speed into it and its own across it (1372 m/s). The
// GPU's passes hold it the same way (held_to_max_speed in sim_kernels.glsl).
inline glm::vec3 held_to_max_speed(glm::vec3 v) {
  const float speed2 = glm::dot(v, v);
  return speed2 > kMaxSpeed * kMaxSpeed ? v * (kMaxSpeed / std::sqrt(speed2)) : v;
}

// Milliseconds spent per stage since the last clear: wall-clock on the CPU, GPU time (from
// timestamps) on the GPU, where a step counts once it has finished (see synchronize() and
// count_finished_steps()); `substeps` counts the substeps of the same steps (on the GPU, of the
// steps that carried timestamps).
struct StageTimes {
  double grid_ms = 0;        // counting sort and reorder
  double neighbours_ms = 0;  // each particle's neighbours listed (GPU: with PBF's first λ,
                             // SPH's densities)
  double predict_ms = 0;     // PBF: forces and prediction (GPU: and the grid's count);
                             // SPH: time integration and collisions
  double solve_ms = 0;       // PBF: the density iterations (the last one sets the velocity);
                             // SPH: density and pressure (CPU), forces
  double velocity_ms = 0;    // PBF, a step's last substep: vorticity, XSPH's sums and the
                             // compression the step leaves; SPH (CPU): CFL bound
  double viscosity_ms = 0;   // PBF: vorticity confinement, on a step's last substep (GPU: and
                             // the state written back; the other substeps' in their last
                             // iteration)
  std::vector<double> iteration_ms;  // PBF: each density iteration, summed over substeps
  std::uint64_t substeps = 0;

  // Every stage (the iterations are part of solve_ms).
  double total_ms() const {
    return grid_ms + neighbours_ms + predict_ms + solve_ms + velocity_ms + viscosity_ms;
  }
};

class Solver {
 public:
  // Throws ParamError for bad params or a tank smaller than one particle spacing.
  Solver(Scene scene, const SolverParams& params);
  virtual ~Solver() = default;
  Solver(const Solver&) = delete;
  Solver& operator=(const Solver&) = delete;

  virtual SolverKind kind() const = 0;
  virtual std::size_t particle_count() const = 0;
  virtual ParticleSet snapshot() const = 0;

  // Where a GPU solver keeps its particles: device addresses of vec4 positions and velocities
  // (w unused) and of float ρ/ρ0 (walls included), in its context, valid until the next add,
  // remove or reset. A renderer on the same
  // context reads them in place. Nothing for a CPU solver.
  struct DeviceParticles {
    std::uint64_t position = 0;
    std::uint64_t velocity = 0;
    std::uint64_t density_ratio = 0;
  };
  virtual std::optional<DeviceParticles> device_particles() const { return std::nullopt; }

  // Advances the simulation by params().time_step, colliders included, in the substeps its rule
  // asks; returns them. A GPU solver may return before the GPU has finished the step; snapshot()
  // and synchronize() wait for it.
  int step() { return step(params().time_step, substeps_for(params().time_step)); }
  // A step of `seconds` in (0, params().time_step] in `substeps` substeps (1 to
  // params().max_substeps): what a frame loop that pays per substep runs, planned with
  // substeps_for(); in slow motion, a shorter step of fewer substeps. The CPU SPH solver adapts
  // each substep to the state it has just computed instead, taking as many as stability needs.
  // Returns the substeps taken. Throws std::invalid_argument outside those ranges.
  int step(float seconds, int substeps);
  // The substeps a step of `seconds` would take now, by the solver's own rule (CFL and, for SPH,
  // the force and viscous bounds), from the newest state it knows.
  virtual int substeps_for(float seconds) = 0;
  // Waits until every step so far has finished and its stage times are counted.
  virtual void synchronize() {}
  // Counts the stage times of the steps that have finished, without waiting for the others.
  virtual void count_finished_steps() {}

  // Inputs. Each throws std::invalid_argument naming what was wrong, and then changes nothing.
  void set_gravity(glm::vec3 gravity);
  void set_colliders(std::span<const Collider> colliders);
  // Adds particles inside the tank; refused as a whole if it would pass params().max_particles.
  void add_particles(std::span<const glm::vec3> positions, std::span<const glm::vec3> velocities);
  // Replaces the whole fluid (a snapshot loaded), checked as add_particles checks and refused as a
  // whole; ids are numbered afresh from 0, the time is kept. As at a scene's start, the substep
  // rule knows nothing of the new fluid and starts from its weight under the gravity set now: set
  // gravity first.
  void replace_particles(std::span<const glm::vec3> positions,
                         std::span<const glm::vec3> velocities);
  // Removes the particles within the sphere; returns how many.
  std::size_t remove_particles_in_sphere(glm::vec3 centre, float radius);
  // Back to the scene's initial particles at t = 0, the substep rule started afresh as in
  // replace_particles. Gravity and colliders stay as they are.
  void reset();
  // Sets the simulated clock: a fluid continued from a snapshot keeps its time. Throws
  // std::invalid_argument for a time that is negative or not finite.
  void set_time(double seconds);

  double time() const { return time_; }
  std::uint64_t steps() const { return steps_; }
  glm::vec3 gravity() const { return gravity_; }
  const std::vector<Collider>& colliders() const { return colliders_; }
  const Scene& scene() const { return scene_; }
  const Box& tank() const { return scene_.tank; }
  // Where particle centres may be: the tank shrunk by a particle radius.
  Box inner_tank() const;
  const SolverParams& params() const { return params_; }
  const FluidConstants& fluid() const { return fluid_; }
  const StageTimes& stage_times() const { return stage_times_; }
  void clear_stage_times() { stage_times_ = {}; }

 protected:
  // Returns the substeps taken.
  virtual int advance(float seconds, int substeps) = 0;
  virtual void append_particles(std::span<const glm::vec3> positions,
                                std::span<const glm::vec3> velocities, std::uint32_t first_id) = 0;
  virtual std::size_t erase_particles_in_sphere(glm::vec3 centre, float radius) = 0;
  // A fluid from outside replaces this one: what the solver learnt of the old one goes.
  virtual void load_particles(const ParticleSet& particles) = 0;

  StageTimes stage_times_;

 private:
  // Throws std::invalid_argument, naming `what`, unless the particles may join a fluid of `total`.
  void check_new_particles(std::string_view what, std::span<const glm::vec3> positions,
                           std::span<const glm::vec3> velocities, std::size_t total) const;

  Scene scene_;
  SolverParams params_;
  FluidConstants fluid_;
  glm::vec3 gravity_;
  std::vector<Collider> colliders_;
  double time_ = 0.0;
  std::uint64_t steps_ = 0;
  std::uint32_t next_id_ = 0;
};

// A state this much denser than the fluid at rest, anywhere, is no state a fluid reaches: its
// particles would not separate, and every step would pay for all their pairs (N particles at one
// point cost N² a step).
inline constexpr float kMaxDensityRatio = 2.0f;
// Throws std::invalid_argument, naming where, when more particles lie in some cube of side two
// kernel radii than kMaxDensityRatio times the fluid at rest holds there (cubes counted from the
// positions' lowest corner), or when a position is not finite or they spread over more than
// 2²¹ cubes along an axis. O(N): for a state from outside (a snapshot), before it is loaded.
void check_density(std::span<const glm::vec3> positions, const FluidConstants& fluid);

class ForkJoinPool;
// `pool`: the threads it steps on. Null: a pool of its own, of params.threads. Solvers that step
// one at a time on one thread (a server's sessions) share one: a pool per solver would keep a
// thread per solver, each spinning a while after its solver's every step, taking the cores from
// the one that is stepping.
std::unique_ptr<Solver> make_cpu_solver(SolverKind kind, Scene scene, const SolverParams& params,
                                        std::shared_ptr<ForkJoinPool> pool = nullptr);
class GpuStepBatch;
// The same solver in Vulkan compute on the context's device. Throws ParamError also when the
// particles would not fit in the device's memory. `batch`: a GpuStepBatch on the same context
// where its steps wait to be submitted together with other solvers' (gpu_step_batch.h); without
// one, each step is submitted as it is taken.
std::unique_ptr<Solver> make_gpu_solver(SolverKind kind, gpu::Context& context, Scene scene,
                                        const SolverParams& params, GpuStepBatch* batch = nullptr);

}  // namespace fluidcast::sim

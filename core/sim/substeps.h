// How finely a step is cut, shared by the CPU and GPU solvers.
#pragma once

#include <algorithm>
#include <array>
#include <glm/glm.hpp>
#include <span>

#include "fluidcast/sim/particles.h"
#include "fluidcast/sim/solver_params.h"

namespace fluidcast::sim {

// PBF's substep rule. A substep is as long as three bounds allow:
// - travel: nothing moves more than pbf_travel · h in one — the fluid (its largest speed plus what
//   gravity adds over the step) or a collider. Beyond about h a particle tunnels through its
//   neighbours; predict() also slows any particle to speed_limit(), so that one flung faster than
//   the plan foresaw cannot either.
// - walls: nothing closes on a tank wall by more than pbf_travel · kWallShareOfSpacing · d (d the
//   particle spacing) in one. The wall stops the layer that reaches it where it is; a layer
//   behind that moved a whole spacing in the same substep lands on it, twice as dense, more than
//   the iterations undo. Only particles that would reach a wall within a step count
//   (wall_approach()); the GPU looks as many steps further ahead as it may have in flight, and
//   takes the largest approach over a step's substeps. A plan, not a limit: a particle flung
//   faster than planned is held only to the travel bound's speed_limit().
// - density: the average compression a step leaves, which Jacobi iterations shrink as Δt², stays
//   within pbf_density_tolerance: each step's measured error sets the longest substep the next
//   may take (it shortens at once when the error was too large and lengthens by at most a tenth
//   a step when it was small, only as far as would leave 0.49 of the tolerance, and only as far
//   as each of the last kRecentSteps steps that left over half of it allows). Figures that
//   arrive late (a GPU's steps in flight) are trusted only while they were well within the
//   tolerance: see count()'s steps_unseen.
//   A fluid just loaded has shown no figures yet, and a column of water at rest compresses at its
//   foot before its average does: the density bound starts from the column's weight (start()).
// The iterations stiffen the fluid as 1/Δt², so only compression may stiffen it: a substep
// shorter than those the density bound alone would cut a whole step into (for travel, walls, a
// finger, or a step of slow motion) takes (Δt / Δt_s)² of its λ and s_corr, Δt_s the density
// bound's substep (stiffness_substep()), and keeps the stiffness that bound chose, except where a
// particle is pressed well past the tolerance (particle_stiffness_share()). Stiffened, a fluid at
// rest releases the compression its longer substeps held as velocity: a 2000-particle pool
// settled at one substep a step jumped from 0.008 to 20 J when a finger flicked past above it at
// 30 m/s (4 substeps a step).
class PbfSubsteps {
 public:
  // The walls' bound: how much of a spacing d a particle may close on a wall in one substep
  // (times pbf_travel). A 1M dam break's front (4.4 m/s) met the far wall at 7 substeps a step by
  // the other bounds (1.1 d each): 72, 111 and 102 % over rest density in three steps; at a whole
  // d (8 substeps) 50, 78 and 35 %; at 0.75 d (11) 22, 20 and 11 %, for 2 % more substeps over
  // its first 0.5 s.
  static constexpr float kWallShareOfSpacing = 0.75f;

  // Substeps lengthen only as far as every one of this many steps observed last allows, of those
  // that left over half the tolerance. A fluid deep enough to bounce cycled under a rule that
  // looked at the last step alone: a pool 57 layers deep (a 1M pool's spacing) sank as its
  // substeps lengthened, was caught compressed (2 % on average, 5 % at most), sprang up as they
  // shortened (5 → 12 a step), was seen uncompressed at the top of its bounce and lengthened them
  // again, over ~15 steps and for good; the H200 showed the 1M pool doing it. Held over 16 steps
  // it settles (7 substeps every step, 0.63 % average and 2.3 % largest error), for 6–12 % more
  // substeps in a dam break (bench/results/substep-window-cpu-2026-11-28.md).
  static constexpr int kRecentSteps = 16;

  // A particle compressed past kPressedFrom tolerances takes more of its λ than its step's
  // stiffness share, all of it from kPressedFrom + kPressedSpan up: water a finger squeezes or a
  // wave drives into a wall resists as stiffly as the short substeps allow, while the rest keeps
  // its stiffness. A pool at rest, at the default Jacobi damping, is compressed by less: at most
  // 1.6 % (20k particles), 1.9 % (57 layers deep), 2.7 % (250 particles at one substep a step;
  // from 2 tolerances, flicked over, it still moved at 0.06 m/s rms on lavapipe, from 3 at 0.019);
  // undamped, a 20k pool holds particles at 3.1 %. A 20k pool with a finger dragged through it at
  // 5 and 10 m/s: largest density error 7.0 and 9.4 % when every cut stiffened it, 11.3 and 19.0 %
  // with the step's share on each particle's whole move, 7.0 and 8.1 % with this.
  static constexpr float kPressedFrom = 3.0f;
  static constexpr float kPressedSpan = 3.0f;

  PbfSubsteps(const SolverParams& params, float kernel_radius);

  // A fluid was loaded (a scene's start, a reset, a snapshot): nothing of it is observed yet. The
  // Jacobi iterations stiffen the fluid like a speed of sound c = h √(k · iterations) / Δt for
  // substeps of Δt; water at rest `depth` m deep along gravity, not yet pressed, is compressed at
  // its foot by its weight, g · depth / c² (as weakly compressible SPH's rule for its speed of
  // sound), before the average compression shows it. The longest substep starts where that equals
  // the tolerance. Gravity that is zero at the load gives no start; switched on later, it finds the
  // bound the figures set.
  void start(std::span<const glm::vec3> positions, glm::vec3 gravity);

  // Substeps of a step of `step` seconds, from the newest speeds known (m/s; a wall approach as
  // largest_wall_approach() measures it). Non-finite speeds give max_substeps. `steps_unseen`:
  // steps still running whose figures are not in yet (a GPU's steps in flight). While the last
  // figures were near the tolerance (above 0.8 of it), each unseen step counts as one that
  // compressed the fluid 1.3 times more (a deep column did, unseen, before it burst):
  // 1.3^(unseen/2) times the substeps, as the error goes as Δt². Near means beyond where
  // lengthening leaves a fluid at rest (0.49 of the tolerance) and well above it: from half of it, a deep pool at
  // rest took the allowance's extra substeps each time steps were in flight, left less error in
  // them, lost the allowance, and bounced with each switch. Before the first figures the bound
  // start() set stands alone.
  int count(float step, float largest_speed, float largest_collider_speed,
            float largest_wall_approach, float gravity, int steps_unseen = 0) const;
  // The substep whose stiffness a substep of `substep` seconds keeps, in a fluid stepped `step`
  // seconds at a time (the solver's time_step, however short a step of slow motion is): as the
  // density bound alone would cut such a step, steps unseen included (on the GPU, those running
  // when the step is queued), never shorter than `substep`; `substep` itself while no bound is
  // set (zero gravity at the load, nothing compressed yet: no compression is held to release).
  // observe() is told this substep, not the one taken.
  float stiffness_substep(float step, float substep, int steps_unseen = 0) const;
  // The fastest a particle may move in a substep of `substep` seconds, m/s.
  float speed_limit(float substep) const { return travel_ / substep; }
  // After a step as stiff as substeps `substep` seconds long (stiffness_substep()) left an average
  // density error `error` (a fraction of ρ0). Non-finite errors are ignored (the speeds then cap
  // the count).
  void observe(float substep, float error);
  // The longest substep the density bound allows now, s (infinite before start() or the first
  // step observed, and after a start without gravity or water).
  float longest_substep() const { return longest_substep_; }

 private:
  float travel_;       // m: pbf_travel · h
  float wall_travel_;  // m: pbf_travel · kWallShareOfSpacing · d
  float tolerance_;    // pbf_density_tolerance
  float kernel_radius_;
  int iterations_;
  int max_substeps_;
  float longest_substep_;
  float last_error_;  // NaN until a step of this fluid was observed
  // The longest substep that each of the last kRecentSteps steps observed would have kept within
  // the tolerance (infinite where none was observed, or it left under half the tolerance), oldest
  // overwritten first.
  std::array<float, kRecentSteps> recent_at_tolerance_;
  int next_recent_ = 0;

  // `substeps` allowed for steps unseen (count()).
  float allow_for_unseen(float substeps, int steps_unseen) const;
};

// The share of its λ and s_corr a substep of `substep` seconds takes to keep the stiffness of one
// of `stiffness_substep` seconds (PbfSubsteps::stiffness_substep()).
inline float stiffness_share(float substep, float stiffness_substep) {
  const float ratio = substep / stiffness_substep;
  return ratio * ratio;
}

// The share of its λ a particle compressed by `compression` (ρ/ρ0 − 1 where the iteration finds
// it) takes, in a step whose share is `step_share`, the density tolerance `tolerance`: more from
// PbfSubsteps::kPressedFrom tolerances up, all of it kPressedSpan above. Scaling λ rather than
// the particle's move keeps each pair's push equal and opposite. The GPU's λ computes the same
// (density_sums.glsl).
inline float particle_stiffness_share(float step_share, float compression, float tolerance) {
  const float pressed = std::clamp((compression - PbfSubsteps::kPressedFrom * tolerance) /
                                       (PbfSubsteps::kPressedSpan * tolerance),
                                   0.0f, 1.0f);
  return step_share + (1.0f - step_share) * pressed;
}

// How fast a particle closes on a wall of `inner` (the box particle centres keep to) that it would
// reach within `reach` seconds at that speed, m/s; 0 for one that would not. The GPU measures the
// same at each substep's end (sim_kernels.glsl, wall_approach in end_pbf_substep).
inline float wall_approach(glm::vec3 position, glm::vec3 velocity, const Box& inner, float reach) {
  float fastest = 0.0f;
  for (int axis = 0; axis < 3; ++axis) {
    const float toward_min = -velocity[axis], toward_max = velocity[axis];
    if (toward_min > 0.0f && position[axis] - inner.min[axis] < toward_min * reach)
      fastest = std::max(fastest, toward_min);
    if (toward_max > 0.0f && inner.max[axis] - position[axis] < toward_max * reach)
      fastest = std::max(fastest, toward_max);
  }
  return fastest;
}

// The largest wall_approach() of a fluid.
float largest_wall_approach(std::span<const glm::vec3> positions,
                            std::span<const glm::vec3> velocities, const Box& inner, float reach);

// SPH: the longest stable substep: the CFL bound with the speed of sound, the force bound
// 0.25 √(h / |a|max), and the viscous bound 0.125 h² / ν.
float sph_stable_substep(float largest_speed, float largest_acceleration,
                         const SolverParams& params, float kernel_radius);

}  // namespace fluidcast::sim

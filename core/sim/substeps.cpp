#include "substeps.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace fluidcast::sim {
namespace {

// A step's error was well under tolerance: the longest substep grows by at most this factor per
// step observed (on the GPU, observations arrive a few steps late: growing from the bound, not
// from the substep observed, keeps a late small error from undoing an earlier large one).
constexpr float kLongestGrowth = 1.1f;

// How much more a step left unseen is taken to have compressed the fluid, near the tolerance.
// Measured in a 175-layer column from rest started at one substep, while no figures came: 1.2–1.6
// a step.
constexpr float kUnseenGrowth = 1.3f;

// Substeps lengthen only as far as would leave this fraction of the tolerance by the Δt² rule,
// not the whole of it: a resting pool sits where one substep leaves just over the tolerance and
// two leave a quarter of it (8000 particles, 4 iterations), and lengthening to the edge made it
// cycle, four steps of one substep every fourteen, the fluid compressing in each (largest
// density error 1 → 3 %) and springing back. 0.7 rather than 0.8: a pool 57 layers deep (a 1M
// pool's spacing) then rests at 0.47 % on average, 1.9 % at most (at 0.8: 0.63 and 2.4 %), for
// 8 substeps a step instead of 7; a 64k dam break, which at 0.8 overshot the tolerance and held
// short substeps for the window's 16 steps after each overshoot, takes 218 over its first 0.5 s
// instead of 239, 670 over 1.5 s instead of 658, its largest error 8.8 % instead of 12.5 %.
constexpr float kLengtheningMargin = 0.7f;

// Figures near the tolerance, for steps unseen: above where lengthening leaves a fluid at rest
// (kLengtheningMargin², 0.49 of the tolerance).
constexpr float kNearShare = 0.8f;
static_assert(kNearShare > kLengtheningMargin * kLengtheningMargin,
              "a fluid at rest must not read as near the tolerance");

// Steps that left more than this share of the tolerance hold the bound for kRecentSteps steps;
// those that left less say nothing against lengthening. From half, a deep pool at rest settles as
// when every step counted, and a 10k dam break at 2 iterations takes 6.5 % more substeps over its
// first 0.5 s than without the hold, not 15 %.
constexpr float kHeldShare = 0.5f;

// A bound of exactly k substeps, worked out in float (a step over a substep the step was cut
// into), can come out a few ulps above k: it still means k.
constexpr float kRoundingSlack = 1e-5f;

// k of start()'s speed of sound, fitted on a 1M-particle dam break's column (0.8 m, 175 layers
// deep, 4 iterations). Started at one substep it compressed at its foot to 71 % over rest density
// while its average stayed under 2 %, and sprang back with 19 J more kinetic energy than its fall
// had released (1.6 times); started at 3, 6 and 10 substeps: 17, 8 and 6 %, 4.3, 0.3 and 0.8 J.
// Not stiffer than needed: a fluid's first positions held a little compression at the walls, which
// a stiff start releases (125k particles started at 8 substeps: 1.2 J of motion in the first step
// for 0.1 J released; fitted before FluidConstants::wall_offset and the walls' edges counted once
// took it away). This k starts the 1M column at 7 substeps and the 125k one at 4.
constexpr float kIterationStiffness = 4.0f;

}  // namespace

PbfSubsteps::PbfSubsteps(const SolverParams& params, float kernel_radius)
    : travel_(params.pbf_travel * kernel_radius),
      wall_travel_(params.pbf_travel * kWallShareOfSpacing * kernel_radius / params.kernel_ratio),
      tolerance_(params.pbf_density_tolerance),
      kernel_radius_(kernel_radius),
      iterations_(params.iterations),
      max_substeps_(params.max_substeps),
      longest_substep_(std::numeric_limits<float>::infinity()),
      last_error_(std::numeric_limits<float>::quiet_NaN()) {
  recent_at_tolerance_.fill(std::numeric_limits<float>::infinity());
}

void PbfSubsteps::start(std::span<const glm::vec3> positions, glm::vec3 gravity) {
  last_error_ = std::numeric_limits<float>::quiet_NaN();
  recent_at_tolerance_.fill(std::numeric_limits<float>::infinity());
  longest_substep_ = std::numeric_limits<float>::infinity();
  const float g = glm::length(gravity);
  if (positions.empty() || !(g > 0.0f)) return;
  const glm::vec3 down = gravity / g;
  float lowest = std::numeric_limits<float>::infinity();
  float highest = -lowest;
  for (const glm::vec3& p : positions) {
    const float height = -glm::dot(p, down);
    lowest = std::min(lowest, height);
    highest = std::max(highest, height);
  }
  const float depth = highest - lowest;
  if (depth > 0.0f && std::isfinite(depth)) {
    longest_substep_ =
        kernel_radius_ *
        std::sqrt(kIterationStiffness * static_cast<float>(iterations_) * tolerance_ / (g * depth));
  }
}

int PbfSubsteps::count(float step, float largest_speed, float largest_collider_speed,
                       float largest_wall_approach, float gravity, int steps_unseen) const {
  // A collider moving faster than the fluid sets the pace too: it must not jump over particles.
  const float speed = std::max(largest_speed + gravity * step, largest_collider_speed);
  const float by_travel = speed * step / travel_;
  const float approach =
      largest_wall_approach > 0.0f ? largest_wall_approach + gravity * step : largest_wall_approach;
  const float by_walls = approach * step / wall_travel_;
  const float by_density = step / longest_substep_;
  // std::max passes over a NaN it does not meet first: a speed that is not finite is refused here.
  if (!std::isfinite(by_travel) || !std::isfinite(by_walls)) return max_substeps_;
  const float substeps = allow_for_unseen(
      std::max({by_travel, by_walls, by_density}) * (1.0f - kRoundingSlack), steps_unseen);
  if (!std::isfinite(substeps)) return max_substeps_;
  return static_cast<int>(std::clamp(std::ceil(substeps), 1.0f, static_cast<float>(max_substeps_)));
}

float PbfSubsteps::allow_for_unseen(float substeps, int steps_unseen) const {
  // NaN, nothing observed yet, is not near: the bound start() set stands alone.
  const bool near_bound = last_error_ > kNearShare * tolerance_;
  if (!near_bound || steps_unseen <= 0) return substeps;
  return std::ceil(substeps) * std::pow(kUnseenGrowth, 0.5f * static_cast<float>(steps_unseen));
}

float PbfSubsteps::stiffness_substep(float step, float substep, int steps_unseen) const {
  if (!std::isfinite(longest_substep_)) return substep;
  const float by_density =
      allow_for_unseen(step / longest_substep_ * (1.0f - kRoundingSlack), steps_unseen);
  return std::max(substep, step / std::max(std::ceil(by_density), 1.0f));
}

void PbfSubsteps::observe(float substep, float error) {
  if (!std::isfinite(error) || !(substep > 0.0f)) return;
  last_error_ = error;
  // The error shrinks at least as Δt² (measured: faster), so this is the longest substep that
  // keeps it within tolerance. Within it the bound does not shorten (below the substep observed,
  // or below itself where it reaches no further than the tolerance: a substep shorter than the
  // bound, rounded to a whole count or set by steps unseen, says nothing against it), and
  // lengthens with a margin, as far as this step and the recent ones held (kHeldShare) all allow.
  const float at_tolerance = error > 0.0f ? substep * std::sqrt(tolerance_ / error)
                                          : std::numeric_limits<float>::infinity();
  recent_at_tolerance_[static_cast<std::size_t>(next_recent_)] =
      error > kHeldShare * tolerance_ ? at_tolerance : std::numeric_limits<float>::infinity();
  next_recent_ = (next_recent_ + 1) % kRecentSteps;
  const float recently = std::min(
      at_tolerance, *std::min_element(recent_at_tolerance_.begin(), recent_at_tolerance_.end()));
  const float allowed = error > tolerance_
                            ? at_tolerance
                            : std::max({substep, std::min(longest_substep_, recently),
                                        kLengtheningMargin * recently});
  longest_substep_ = std::min(allowed, kLongestGrowth * longest_substep_);
}

float largest_wall_approach(std::span<const glm::vec3> positions,
                            std::span<const glm::vec3> velocities, const Box& inner, float reach) {
  float fastest = 0.0f;
  for (std::size_t i = 0; i < positions.size(); ++i) {
    fastest = std::max(fastest, wall_approach(positions[i], velocities[i], inner, reach));
  }
  return fastest;
}

float sph_stable_substep(float largest_speed, float largest_acceleration,
                         const SolverParams& params, float kernel_radius) {
  const float h = kernel_radius;
  float dt = params.cfl_number * h / (params.sound_speed + largest_speed);
  if (largest_acceleration > 0.0f) dt = std::min(dt, 0.25f * std::sqrt(h / largest_acceleration));
  if (params.sph_viscosity > 0.0f) {
    const float kinematic_viscosity = params.sph_viscosity / params.rest_density;
    dt = std::min(dt, 0.125f * h * h / kinematic_viscosity);
  }
  return dt;
}

}  // namespace fluidcast::sim

// A dragging finger's sphere in the fluid: where the fluid has it, and how it moves towards the
// finger's point each tick. It moves in simulated time at most as fast as the hand has moved in
// wall time during this drag, so that a fluid in slow motion sees the finger in slow motion too.
// Chasing the finger's point over each tick's wall time instead made it faster the slower the
// fluid ran: the gap it left grew to the hand's travel in a tick divided by the simulation speed,
// and so did its speed, which cut the steps into more substeps (the travel bound), which slowed
// the fluid further. A new sphere grows in (kGrowSeconds). Pure: the server's session and the
// page's local fluid say when the fluid advanced and where the finger is.
#pragma once

#include <cstddef>
#include <deque>
#include <glm/glm.hpp>
#include <optional>

#include "fluidcast/sim/solver.h"

namespace fluidcast::sim {

class FingerCollider {
 public:
  // The hand's speed is the path the finger's point travelled between the touch events of about
  // this much of the latest wall time, over the time between them: long enough to smooth events
  // that the network bunches, short enough to follow a flick.
  static constexpr double kHandWindowSeconds = 0.2;
  // The shortest wall time a speed is taken over, the interval of touch events at 20 a second:
  // two events that arrive a tick apart may have left the hand 50 ms apart.
  static constexpr double kShortestSpan = 0.05;

  // Samples kept at most, whatever the ticks' rate (the window holds 24 at 120 ticks a second).
  static constexpr std::size_t kMostSamples = 64;
  // A new sphere grows to its radius over this much simulated time. Appearing whole in the water
  // it threw what it displaced out within a substep (v = Δx/Δt, not capped as the density
  // corrections are): a finger held still in a 2000-particle pool raised its mean v² fivefold.
  static constexpr double kGrowSeconds = 0.1;
  // However fast the hand: within what Solver::set_colliders takes of a collider (kMaxSpeed).
  static constexpr float kFastest = 0.5f * kMaxSpeed;

  // A drag begins with its sphere at the finger's point.
  explicit FingerCollider(glm::vec3 point);

  // Where the fluid has the sphere now, m.
  glm::vec3 centre() const { return centre_; }
  // The sphere is where the finger's point was at the last tick. A lifted finger's sphere goes on
  // until it is: in slow motion it trails the hand, and a stroke would otherwise end short.
  bool arrived() const { return arrived_; }

  struct Motion {
    glm::vec3 centre;    // where the fluid has the sphere as the tick's steps begin, m
    glm::vec3 velocity;  // m/s, over the tick's simulated seconds
    // Of its radius, the sphere has grown to this over the tick (kGrowSeconds); 0: not in the
    // fluid yet (a drag that began while the fluid was paused).
    float size;
    // The solver's collider for a sphere of full radius `radius` m; nothing while it has no size
    // (Solver::set_colliders refuses a radius of 0).
    std::optional<Collider> collider(float radius) const {
      if (!(size * radius > 0.0f)) return std::nullopt;
      return Collider{centre, size * radius, velocity};
    }
  };
  // A tick that simulates `seconds` of the `elapsed` wall seconds since the last, with the
  // finger's point at `target`: the sphere heads for it, to reach it within the tick's simulated
  // seconds where it may go that fast: at most at the fastest the hand has moved in this drag
  // (and kFastest). The centre then moves on by `seconds` of that velocity, never past the
  // finger's point. A tick that simulates nothing (paused) still sees where the hand went.
  // Seconds that are not finite and positive count as none.
  Motion follow(glm::vec3 target, double seconds, double elapsed);

  // The fastest the hand has moved in this drag so far, m/s of wall time.
  float hand_speed() const { return fastest_hand_; }

 private:
  struct Sample {
    double time;  // wall seconds since the drag began
    glm::vec3 point;
  };
  void record(glm::vec3 target, double elapsed);

  glm::vec3 centre_;
  double now_ = 0.0;            // wall seconds since the drag began
  double simulated_ = 0.0;      // simulated seconds since the drag began
  std::deque<Sample> samples_;  // where the finger's point moved, from just before the window on
  float fastest_hand_ = 0.0f;
  bool arrived_ = true;
};

}  // namespace fluidcast::sim

// A session's finger spheres: each viewer's live drag, and the strokes still finishing after
// their finger lifted (sim::FingerCollider::arrived). One sphere a viewer cut a stroke short
// whenever the next began before the last had caught up with its finger, as quick strokes in
// slow motion do. Pure: the session says where the fingers are and how far the fluid advanced.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "fluidcast/sim/finger_collider.h"
#include "fluidcast/sim/solver.h"

namespace fluidcast::server {

class FingerStrokes {
 public:
  // A viewer's finger on the fluid this tick: which of its drags, and its point in the scene.
  struct Finger {
    std::uint32_t viewer;
    std::uint64_t drag;
    glm::vec3 point;
  };

  // One tick that simulates `seconds` of the `elapsed` wall seconds since the last (as
  // FingerCollider::follow), with the fingers' points this tick in `fingers`: the live drags'
  // first, then the last points of drags that ended since the last tick (they finish from the
  // next). Returns the solver's colliders, spheres of full radius `radius`, in that order, then the
  // finishing strokes', the most recently lifted first, at most sim::kMaxColliders; the spheres
  // past that (the longest finishing) are dropped.
  std::vector<sim::Collider> move(std::span<const Finger> fingers, double seconds, double elapsed,
                                  float radius);
  // A fluid rebuilt, reset or loaded: the spheres grow into it afresh.
  void clear() { strokes_.clear(); }
  std::size_t size() const { return strokes_.size(); }

 private:
  struct Stroke {
    std::uint32_t viewer;
    std::uint64_t drag;
    sim::FingerCollider sphere;
    glm::vec3 target;  // the finger's last point
  };
  std::vector<Stroke> strokes_;  // live drags first, then the finishing, most recently lifted first
};

}  // namespace fluidcast::server

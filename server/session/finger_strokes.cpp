#include "finger_strokes.h"

#include <algorithm>
#include <utility>

namespace fluidcast::server {

std::vector<sim::Collider> FingerStrokes::move(std::span<const Finger> fingers, double seconds,
                                               double elapsed, float radius) {
  std::vector<Stroke> kept;
  std::vector<bool> followed(strokes_.size(), false);
  for (const Finger& finger : fingers) {
    const auto same = [&](const Stroke& s) {
      return s.viewer == finger.viewer && s.drag == finger.drag;
    };
    const auto found = std::find_if(strokes_.begin(), strokes_.end(), same);
    if (found == strokes_.end()) {
      kept.push_back({finger.viewer, finger.drag, sim::FingerCollider(finger.point), finger.point});
    } else {
      followed[std::size_t(found - strokes_.begin())] = true;
      kept.push_back(std::move(*found));
      kept.back().target = finger.point;
    }
  }
  for (std::size_t k = 0; k < strokes_.size(); ++k) {
    if (!followed[k] && !strokes_[k].sphere.arrived()) kept.push_back(std::move(strokes_[k]));
  }
  if (kept.size() > sim::kMaxColliders) {
    kept.erase(kept.begin() + sim::kMaxColliders, kept.end());
  }

  std::vector<sim::Collider> colliders;
  for (Stroke& stroke : kept) {
    const auto motion = stroke.sphere.follow(stroke.target, seconds, elapsed);
    if (const auto collider = motion.collider(radius)) colliders.push_back(*collider);
  }
  strokes_ = std::move(kept);
  return colliders;
}

}  // namespace fluidcast::server

#include "fluidcast/sim/finger_collider.h"

#include <algorithm>
#include <cmath>

namespace fluidcast::sim {

FingerCollider::FingerCollider(glm::vec3 point) : centre_(point), samples_{{0.0, point}} {}

void FingerCollider::record(glm::vec3 target, double elapsed) {
  if (elapsed > 0.0 && std::isfinite(elapsed)) now_ += elapsed;
  // Only where the finger's point moved: a tick between two touch events is not a hand at rest.
  if (samples_.back().point == target) return;
  arrived_ = false;  // until a tick that simulates time takes the sphere there
  samples_.push_back({now_, target});
  // Keep the newest sample from before the window: the path is then measured over all of it.
  while (samples_.size() > 2 &&
         (samples_[1].time <= now_ - kHandWindowSeconds || samples_.size() > kMostSamples)) {
    samples_.pop_front();
  }
  double path = 0.0;
  for (std::size_t k = 1; k < samples_.size(); ++k) {
    path += glm::distance(samples_[k - 1].point, samples_[k].point);
  }
  // The first move after a rest began at most kShortestSpan before it was seen, not at the rest.
  const double start = std::max(samples_[0].time, samples_[1].time - kShortestSpan);
  const double span = std::max(now_ - start, kShortestSpan);
  fastest_hand_ = std::max(fastest_hand_, static_cast<float>(path / span));
}

FingerCollider::Motion FingerCollider::follow(glm::vec3 target, double seconds, double elapsed) {
  record(target, elapsed);
  const auto size = [this] { return static_cast<float>(std::min(1.0, simulated_ / kGrowSeconds)); };
  if (!(seconds > 0.0 && std::isfinite(seconds))) return {centre_, glm::vec3(0.0f), size()};
  simulated_ += seconds;
  const glm::vec3 gap = target - centre_;
  const float distance = glm::length(gap);
  const float most = std::min(fastest_hand_, kFastest) * static_cast<float>(seconds);
  arrived_ = !(distance > most);
  const glm::vec3 travel = arrived_ ? gap : gap * (most / distance);
  if (!is_finite(travel)) return {centre_, glm::vec3(0.0f), size()};
  const Motion motion{centre_, travel / static_cast<float>(seconds), size()};
  centre_ += travel;
  return motion;
}

}  // namespace fluidcast::sim

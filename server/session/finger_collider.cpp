#include "session/finger_collider.h"

#include <algorithm>

namespace fluidcast::server {

FingerCollider::FingerCollider(glm::vec3 point, std::uint64_t drag)
    : centre_(point), drag_(drag), samples_{{0.0, point}} {}

void FingerCollider::record(glm::vec3 target, double elapsed) {
  now_ += std::max(elapsed, 0.0);
  // Only where the finger's point moved: a tick between two touch events is not a hand at rest.
  if (samples_.back().point == target) return;
  samples_.push_back({now_, target});
  // Keep the newest sample from before the window: the path is then measured over all of it.
  while (samples_.size() > 2 && samples_[1].time <= now_ - kHandWindowSeconds) samples_.pop_front();
  double path = 0.0;
  for (std::size_t k = 1; k < samples_.size(); ++k) {
    path += glm::distance(samples_[k - 1].point, samples_[k].point);
  }
  const double span = std::max(now_ - samples_.front().time, kShortestSpan);
  fastest_hand_ = std::max(fastest_hand_, static_cast<float>(path / span));
}

FingerCollider::Motion FingerCollider::follow(glm::vec3 target, double seconds, double elapsed,
                                              float speed_limit) {
  record(target, elapsed);
  glm::vec3 velocity(0.0f);
  if (seconds > 0.0) {
    velocity = (target - centre_) / static_cast<float>(seconds);
    const float speed = glm::length(velocity);
    const float fastest = std::min(fastest_hand_, speed_limit);
    if (speed > fastest) velocity *= fastest / speed;
  }
  const Motion motion{centre_, velocity};
  centre_ += velocity * static_cast<float>(seconds);
  return motion;
}

}  // namespace fluidcast::server

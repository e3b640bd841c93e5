#include "gestures.h"

#include <algorithm>
#include <iterator>

namespace fluidcast::server {
namespace {

struct Pair {
  glm::vec2 centre;
  float spread;
};

Pair pair_of(const std::map<std::uint32_t, glm::vec2>& pointers) {
  const glm::vec2 a = pointers.begin()->second, b = std::next(pointers.begin())->second;
  return {0.5f * (a + b), glm::length(a - b)};
}

}  // namespace

GestureChange Gestures::apply(const v1::PointerEvent& event) {
  GestureChange change;
  const glm::vec2 at(event.x(), event.y());
  const std::uint32_t id = event.pointer_id();
  switch (event.phase()) {
    case v1::PointerEvent::DOWN: {
      const std::optional<glm::vec2> dragged = drag();
      pointers_[id] = at;
      if (pointers_.size() > 1) multi_touch_ = true;
      change.drag_started = touches_fluid_ && pointers_.size() == 1;
      // A second finger joined, or the dragging one came down again (its UP was lost).
      if (dragged && (!dragging() || change.drag_started)) change.drag_ended_at = dragged;
      break;
    }
    case v1::PointerEvent::MOVE: {
      const auto found = pointers_.find(id);
      if (found == pointers_.end()) break;  // a move of a pointer that never went down
      if (pointers_.size() == 2) {
        const Pair before = pair_of(pointers_);
        found->second = at;
        const Pair after = pair_of(pointers_);
        change.yaw_degrees = -(after.centre.x - before.centre.x) * kOrbitDegreesPerFrame;
        change.pitch_degrees = (after.centre.y - before.centre.y) * kOrbitDegreesPerFrame;
        if (before.spread > 1e-3f && after.spread > 1e-3f) {
          change.zoom = std::clamp(before.spread / after.spread, 0.5f, 2.0f);
        }
      } else {
        if (!touches_fluid_ && pointers_.size() == 1) {
          change.yaw_degrees = -(at.x - found->second.x) * kOrbitDegreesPerFrame;
          change.pitch_degrees = (at.y - found->second.y) * kOrbitDegreesPerFrame;
        }
        found->second = at;
      }
      break;
    }
    case v1::PointerEvent::UP:
    case v1::PointerEvent::CANCEL: {
      const auto found = pointers_.find(id);
      if (found == pointers_.end()) break;
      if (dragging()) {
        change.drag_ended_at = event.phase() == v1::PointerEvent::UP ? at : found->second;
      }
      pointers_.erase(found);
      if (pointers_.empty()) multi_touch_ = false;
      break;
    }
    default:
      break;
  }
  return change;
}

std::optional<glm::vec2> Gestures::drag() const {
  if (dragging()) return pointers_.begin()->second;
  return std::nullopt;
}

}  // namespace fluidcast::server

#include "drag_probe.h"

#include <utility>

#include "fluidcast/sim/solver.h"

namespace fluidcast::server {

void DragProbe::start() {
  depth_.reset();
  frames_ = 0;
  ++drags_;
}

void DragProbe::lift(glm::vec2 finger, const render::OrbitCamera& camera, float aspect) {
  if (const auto last = point(finger, camera, aspect)) {
    if (lifted_.size() == sim::kMaxColliders) lifted_.erase(lifted_.begin());
    lifted_.push_back(*last);
  }
  depth_.reset();
}

DragProbe::Points DragProbe::points(std::optional<glm::vec2> finger,
                                    const render::OrbitCamera& camera, float aspect) {
  Points points{std::exchange(lifted_, {}), std::nullopt};
  if (finger) {
    points.live = point(*finger, camera, aspect);
  } else {
    depth_.reset();
  }
  return points;
}

std::optional<DragProbe::DragPoint> DragProbe::point(glm::vec2 finger,
                                                     const render::OrbitCamera& camera,
                                                     float aspect) {
  if (!depth_) {
    if (frames_ < kProbeFrames) return std::nullopt;  // the probe has not answered yet
    depth_ = camera.distance;
  }
  return DragPoint{render::unproject(camera.view(), camera.projection(aspect), finger, *depth_),
                   drags_};
}

void DragProbe::probed(std::uint64_t drag, std::optional<glm::vec3> hit,
                       const render::OrbitCamera& camera) {
  if (drag != drags_ || depth_) return;
  ++frames_;
  if (hit) depth_ = -(camera.view() * glm::vec4(*hit, 1.0f)).z;
}

}  // namespace fluidcast::server

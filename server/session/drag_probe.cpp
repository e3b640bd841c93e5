#include "drag_probe.h"

namespace fluidcast::server {

void DragProbe::start() {
  depth_.reset();
  frames_ = 0;
  ++drags_;
}

std::optional<DragProbe::DragPoint> DragProbe::point(std::optional<glm::vec2> finger,
                                                     const render::OrbitCamera& camera,
                                                     float aspect) {
  if (!finger) {
    depth_.reset();
    return std::nullopt;
  }
  if (!depth_) {
    if (frames_ < kProbeFrames) return std::nullopt;  // the probe has not answered yet
    depth_ = camera.distance;
  }
  return DragPoint{render::unproject(camera.view(), camera.projection(aspect), *finger, *depth_),
                   drags_};
}

void DragProbe::probed(std::optional<glm::vec3> hit, const render::OrbitCamera& camera) {
  if (depth_) return;
  ++frames_;
  if (hit) depth_ = -(camera.view() * glm::vec4(*hit, 1.0f)).z;
}

}  // namespace fluidcast::server

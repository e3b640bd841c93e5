// Where a finger that drags holds the fluid. When a drag starts, the renderer is asked to read the
// fluid's surface back under the finger; the depth it finds (along the view axis) is the one the
// fluid is held at while the finger moves, so the finger takes the water it touched rather than a
// point behind it. When the probe finds nothing within kProbeFrames frames (points drawn, or the
// finger off the fluid), the camera's target depth is taken instead. Pure: the Viewer asks its
// renderer to probe and tells this what came back.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <optional>

#include "fluidcast/render/camera.h"

namespace fluidcast::server {

class DragProbe {
 public:
  static constexpr int kProbeFrames = 3;

  // The finger's place in the scene, and which drag it is (they are counted, so that the session
  // starts each one afresh).
  struct DragPoint {
    glm::vec3 point;
    std::uint64_t drag;
  };

  // A finger started a drag.
  void start();
  // Where the drag holds the fluid now: `finger` is its point of the frame (nothing when no finger
  // drags); nothing while the probe has not answered yet.
  std::optional<DragPoint> point(std::optional<glm::vec2> finger, const render::OrbitCamera& camera,
                                 float aspect);
  // A frame that probed came back: `hit` where it met the surface, if it did, seen by `camera`.
  void probed(std::optional<glm::vec3> hit, const render::OrbitCamera& camera);

 private:
  std::optional<float> depth_;
  int frames_ = 0;
  std::uint64_t drags_ = 0;
};

}  // namespace fluidcast::server

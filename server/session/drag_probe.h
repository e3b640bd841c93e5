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
#include <vector>

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
  // The drag's finger lifted at `finger` (its point of the frame): its last point is given by the
  // next points(), beside a drag begun since, so that the stretch it moved since the last tick is
  // followed (nothing when the probe had not answered yet, as for points()).
  void lift(glm::vec2 finger, const render::OrbitCamera& camera, float aspect);
  struct Points {
    std::vector<DragPoint> ended;   // oldest first, the last sim::kMaxColliders at most
    std::optional<DragPoint> live;  // none while the probe has not answered yet
  };
  // Asked once a tick: the last points of the drags that ended since the last call, and where the
  // live drag holds the fluid; `finger` is its point of the frame (nothing when no finger drags).
  Points points(std::optional<glm::vec2> finger, const render::OrbitCamera& camera, float aspect);
  // The drag a frame probes for now (a frame's probe answers for the drag it was drawn for).
  std::uint64_t drag() const { return drags_; }
  // A frame that probed for `drag` came back: `hit` where it met the surface, if it did, seen by
  // `camera`. A frame drawn for an earlier drag counts for nothing.
  void probed(std::uint64_t drag, std::optional<glm::vec3> hit, const render::OrbitCamera& camera);

 private:
  std::optional<DragPoint> point(glm::vec2 finger, const render::OrbitCamera& camera, float aspect);

  std::vector<DragPoint> lifted_;
  std::optional<float> depth_;
  int frames_ = 0;
  std::uint64_t drags_ = 0;
};

}  // namespace fluidcast::server

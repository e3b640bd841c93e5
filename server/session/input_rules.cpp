#include "input_rules.h"

#include "fluidcast/render/camera.h"
#include "fluidcast/render/frame_renderer.h"
#include "fluidcast/sim/scene.h"
#include "fluidcast/sim/solver.h"

namespace fluidcast::server {
namespace {

void set(v1::Range& range, double min, double max) {
  range.set_min(min);
  range.set_max(max);
}

}  // namespace

v1::InputRules input_rules(bool mc_drawable) {
  using render::OrbitCamera;
  v1::InputRules rules;
  set(*rules.mutable_camera_distance(), 0.0, OrbitCamera::kMaxDistance);
  set(*rules.mutable_camera_pitch_degrees(), -OrbitCamera::kMaxPitchDegrees,
      OrbitCamera::kMaxPitchDegrees);
  set(*rules.mutable_camera_field_of_view_degrees(), OrbitCamera::kMinFieldOfView,
      OrbitCamera::kMaxFieldOfView);
  set(*rules.mutable_tilt_gravity(), kMinTiltGravity, kMaxTiltGravity);
  rules.set_pointer_ids(kPointerIds);
  rules.set_max_jpeg_quality(kMaxJpegQuality);
  rules.set_max_state_particles(kMaxStateParticles);
  set(*rules.mutable_snapshot_seconds(), 0.0, kMaxSnapshotSeconds);
  for (auto name : sim::scene_names()) rules.add_scenes(std::string(name));
  for (auto name : sim::solver_names()) rules.add_solvers(std::string(name));
  // A viewer that asks for a renderer the device cannot draw gets SSFR (Frame.renderer).
  for (auto name : render::renderer_names()) {
    if (mc_drawable || name != "mc") rules.add_renderers(std::string(name));
  }
  return rules;
}

}  // namespace fluidcast::server

#include "viewer.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "fluidcast/gpu/vk_check.h"
#include "refusal.h"

namespace fluidcast::server {
namespace {

// Called while `error` is handled: a GPU out of memory for this viewer's frames is its request's
// failure, which ends its stream alone; any other (a lost device) is rethrown for the session.
Refusal refusal_for_frames(const gpu::VulkanError& error, std::uint32_t width,
                           std::uint32_t height) {
  if (!error.out_of_memory()) throw;
  return no_gpu_memory("Viewport",
                       "frames of " + std::to_string(width) + "x" + std::to_string(height), error,
                       "ask for a smaller one");
}

// A viewport beyond the server's largest frame, scaled down to fit it with its shape kept: a
// phone's portrait screen asks for frames taller than a server limited to landscape's 1920×1080
// draws. Frames say their size.
FlowControl::Size within_limits(const v1::Viewport& viewport, const ServerLimits& limits) {
  const double scale = std::min({1.0, double(limits.max_width) / double(viewport.width()),
                                 double(limits.max_height) / double(viewport.height())});
  const auto scaled = [scale](std::uint32_t pixels, std::uint32_t most) {
    return std::clamp<std::uint32_t>(static_cast<std::uint32_t>(std::lround(pixels * scale)), 1,
                                     most);
  };
  return {scaled(viewport.width(), limits.max_width), scaled(viewport.height(), limits.max_height)};
}

// Whether frames of `to` are turned from frames of `from` (one portrait, the other landscape);
// not from no size yet.
bool turned_from(FlowControl::Size from, FlowControl::Size to) {
  return from.width != 0 && (to.width > to.height) != (from.width > from.height);
}

}  // namespace

Viewer::Viewer(gpu::Context& context, std::uint32_t id, Seat seat, const v1::Viewport& viewport,
               const v1::Quality& quality, const ServerLimits& limits,
               std::shared_ptr<ViewerSink> sink)
    : context_(&context),
      id_(id),
      seat_(std::move(seat)),
      limits_(&limits),
      sink_(std::move(sink)) {
  apply_quality(quality);
  apply_viewport(viewport);
}

Viewer::~Viewer() {
  if (renderer_) context_->retire(std::move(renderer_));
}

void Viewer::aim_size(std::uint32_t width, std::uint32_t height) {
  if (renderer_ && unfit_size_ == FlowControl::Size{width, height}) return;
  aimed_width_ = width;
  aimed_height_ = height;
  if (!renderer_) make_renderer(width, height);
}

bool Viewer::settle_size(Clock::time_point now) {
  if (aimed_width_ == render_width_ && aimed_height_ == render_height_) return false;
  if (now - last_resize_ < kResizeEvery) return false;
  last_resize_ = now;
  try {
    make_renderer(aimed_width_, aimed_height_);
  } catch (const Refusal&) {  // no GPU memory for that size: the frames keep the one they have
    unfit_size_ = FlowControl::Size{aimed_width_, aimed_height_};
    aimed_width_ = render_width_;
    aimed_height_ = render_height_;
  }
  return true;
}

void Viewer::make_renderer(std::uint32_t width, std::uint32_t height) {
  std::unique_ptr<render::FrameRenderer> renderer;
  try {
    renderer = std::make_unique<render::FrameRenderer>(*context_, width, height);
  } catch (const gpu::VulkanError& e) {
    throw refusal_for_frames(e, width, height);
  }
  // Frames go to the JPEG encoder only: converted and subsampled on the GPU.
  renderer->format = render::FrameRenderer::FrameFormat::yuv420;
  if (renderer_) {
    // Screen-space passes cost by the pixel: the new size's frames are priced as such at once.
    frame_cost_.scale(double(width) * double(height) /
                      (double(render_width_) * double(render_height_)));
    renderer->probe = renderer_->probe;
    context_->retire(std::move(renderer_));  // its frames in flight, of the old size, are dropped
  }
  in_flight_.clear();
  unfit_size_.reset();
  renderer_ = std::move(renderer);
  renderer_warm_ = false;
  render_width_ = width;
  render_height_ = height;
}

void Viewer::apply_viewport(const v1::Viewport& viewport) {
  const FlowControl::Size size = within_limits(viewport, *limits_);
  const bool turned = turned_from({width_, height_}, size);
  width_ = size.width;
  height_ = size.height;
  flow_.ask_size({width_, height_});
  aim_size(width_, height_);
  // A phone turned between portrait and landscape: the tank in view again.
  if (turned) camera_.fit(tank_, float(width_) / float(height_));
}

void Viewer::apply_quality(const v1::Quality& quality) {
  flow_.ask(quality.max_fps() == 0 ? limits_->target_fps : quality.max_fps(),
            quality.jpeg_quality(), quality.adaptive());
  renderer_kind_ = quality.renderer().empty() ? render::RendererKind::automatic
                                              : render::parse_renderer(quality.renderer());
  if (renderer_) aim_size(width_, height_);
}

void Viewer::apply_camera(const v1::Camera& camera) {
  camera_.yaw_degrees = camera.yaw_degrees();
  camera_.pitch_degrees = camera.pitch_degrees();
  camera_.distance = camera.distance();
  if (camera.field_of_view_degrees() != 0.0f) {
    camera_.field_of_view_degrees = camera.field_of_view_degrees();
  }
  orbit_.clamp(camera_);
}

void Viewer::resume_view(const View& seen) {
  camera_ = seen.camera;
  if (turned_from(seen.size, {width_, height_})) camera_.fit(tank_, float(width_) / float(height_));
}

void Viewer::look_at(const sim::Box& tank) {
  tank_ = tank;
  orbit_ = render::orbit_limits(tank);
  camera_.fit(tank, float(width_) / float(height_));
}

void Viewer::reset_view() {
  camera_ = render::OrbitCamera{};
  camera_.fit(tank_, float(width_) / float(height_));
}

void Viewer::apply_pointer(const v1::PointerEvent& event) {
  const GestureChange change = gestures_.apply(event);
  if (change.drag_ended_at) drag_.lift(*change.drag_ended_at, camera_, aspect());
  if (change.drag_started) drag_.start();
  camera_.yaw_degrees = std::remainder(camera_.yaw_degrees + change.yaw_degrees, 360.0f);
  camera_.pitch_degrees += change.pitch_degrees;
  camera_.distance *= change.zoom;
  orbit_.clamp(camera_);
}

glm::vec3 Viewer::gravity_from_tilt(const v1::Tilt& tilt) const {
  // The camera's axes in the world: right, up, and towards the viewer.
  const glm::mat3 camera_to_world = glm::transpose(glm::mat3(camera_.view()));
  return camera_to_world * glm::vec3(tilt.x(), tilt.y(), tilt.z());
}

DragProbe::Points Viewer::drag_points() {
  const std::optional<glm::vec2> finger = gestures_.drag();
  renderer_->probe = finger;
  return drag_.points(finger, camera_, aspect());
}

bool Viewer::due(Clock::time_point now) const {
  return *encoding_ < kMaxFramesEncoding && flow_.due(now);
}

void Viewer::note_input(std::uint64_t event_id, Clock::time_point received) {
  if (event_id < newest_input_) return;
  newest_input_ = event_id;
  newest_input_received_ = received;
}

double Viewer::input_wait_ms(Clock::time_point tick_start) {
  if (newest_input_received_ == Clock::time_point{} || input_shown_ == newest_input_) return 0.0;
  input_shown_ = newest_input_;
  return std::max(
      0.0, std::chrono::duration<double, std::milli>(tick_start - newest_input_received_).count());
}

void Viewer::submit(const render::ParticleView& particles, const sim::Box& tank, Shows shows,
                    Clock::time_point now) {
  flow_.rendered(now);
  // A renderer the device cannot draw falls back to ssfr, and the frame says so.
  const render::RendererKind kind = renderer_->drawable(renderer_kind_, particles.count);
  try {
    renderer_->submit(kind, particles, tank, camera_);  // a renderer makes its passes' targets
  } catch (const gpu::VulkanError& e) {                 // on first use
    throw refusal_for_frames(e, render_width_, render_height_);
  }
  shows.renderer = std::string(render::renderer_name(kind));
  if (renderer_->probe) shows.probed_drag = drag_.drag();
  shows.submitted = Clock::now();
  in_flight_.push_back(std::move(shows));
}

bool Viewer::frame_finished() { return !in_flight_.empty() && renderer_->oldest_finished(); }

std::optional<Viewer::Finished> Viewer::take_finished(Clock::time_point now) {
  if (in_flight_.empty()) return std::nullopt;
  codec::Image image = renderer_->take_oldest();
  const auto taken = Clock::now();
  const double queue_ms =
      std::chrono::duration<double, std::milli>(taken - in_flight_.front().submitted).count();
  Finished finished{
      std::move(image), flow_.produced(now), std::move(in_flight_.front()), renderer_->last_times(),
      queue_ms,         flow_.jpeg_quality()};
  in_flight_.pop_front();
  // A renderer's first frame draws the whole scene (the tank and floor, kept while the camera
  // stays) and, on some drivers, compiles its pipelines: not what its frames cost.
  if (renderer_warm_) frame_cost_.add(gpu_ms(finished));
  renderer_warm_ = true;
  if (finished.shows.probed_drag) {
    drag_.probed(*finished.shows.probed_drag, renderer_->last_probe_hit(), camera_);
  }
  return finished;
}

void Viewer::acknowledge(std::uint64_t sequence, Clock::time_point now) {
  flow_.acknowledge(sequence, now);
  const FlowControl::Size size = flow_.render_size();
  aim_size(size.width, size.height);
}

}  // namespace fluidcast::server

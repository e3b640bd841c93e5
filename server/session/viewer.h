// One client watching a session: its own camera, frame size, renderer and JPEG quality, its
// gestures, and the renderer that FlowControl's decisions (rate, quality, size) are applied to.
// Lives on the GPU worker's thread; only its sink is reached from elsewhere.
#pragma once

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <string>

#include "access.h"
#include "drag_probe.h"
#include "flow_control.h"
#include "fluidcast/render/camera.h"
#include "fluidcast/render/frame_renderer.h"
#include "fluidcast/sim/solver.h"
#include "gestures.h"
#include "gpu_budget.h"
#include "server_limits.h"
#include "viewer_sink.h"

namespace fluidcast::server {

// How a viewer's stream ended: dropped (a lost network, or ended by the server: it may resume) or
// left (the client closed it on purpose: it will not).
enum class Departure { dropped, left };

// What a viewer may do, and the key that brings it back after a dropped connection.
struct Seat {
  Access access = Access::view;
  std::string resume_key = new_key();
};

class Viewer {
 public:
  // Frames of this viewer waiting for or in the JPEG encoders, beyond which none is rendered:
  // a client that never acknowledges cannot make the encoder queue grow.
  static constexpr int kMaxFramesEncoding = 2;

  Viewer(gpu::Context& context, std::uint32_t id, Seat seat, const v1::Viewport& viewport,
         const v1::Quality& quality, const ServerLimits& limits, std::shared_ptr<ViewerSink> sink);
  // Its renderer is retired: its frames in flight finish without anyone waiting for them.
  ~Viewer();
  Viewer(const Viewer&) = delete;
  Viewer& operator=(const Viewer&) = delete;

  std::uint32_t id() const { return id_; }
  const Seat& seat() const { return seat_; }
  ViewerSink& sink() const { return *sink_; }
  const std::shared_ptr<ViewerSink>& shared_sink() const { return sink_; }

  // Input (validated already). Pointer events may move the camera or start a drag.
  void apply_pointer(const v1::PointerEvent& event);
  void apply_quality(const v1::Quality& quality);
  void apply_viewport(const v1::Viewport& viewport);
  void apply_camera(const v1::Camera& camera);
  void acknowledge(std::uint64_t sequence, Clock::time_point now);
  // The world's gravity for a device's measured one, through this viewer's camera.
  glm::vec3 gravity_from_tilt(const v1::Tilt& tilt) const;
  // Looks at the whole of `tank` (fitted to the frame's shape) and keeps gestures and cameras set
  // outright within its orbit limits.
  void look_at(const sim::Box& tank);
  // The camera back to where a new viewer's starts, the whole tank in view.
  void reset_view();

  // Where this viewer's fingers hold the fluid, in the scene (DragProbe::points: the drags that
  // ended since the last tick, at their last point, then the live one): the session moves each
  // finger's sphere there in simulated time. Asked once a tick; also points the renderer's probe
  // at the live finger, for the frames that find the depth.
  DragProbe::Points drag_points();

  // A new frame size (asked for, or chosen by adaptation) takes a new renderer, made here at most
  // once per kResizeEvery, the newest size winning: a client that keeps resizing cannot keep the
  // worker making renderers. True when it tried (the session charges its time). Where the GPU has
  // no memory for the new size, the frames keep the size they have (they say it), and that size
  // is not tried again until another has been made; a new viewer's first renderer, and frames
  // the GPU has no memory to draw, throw a Refusal (RESOURCE_EXHAUSTED) instead: the viewer
  // ends, its session goes on.
  bool settle_size(Clock::time_point now);
  static constexpr auto kResizeEvery = std::chrono::milliseconds(250);

  // Whether to render a frame now: FlowControl says one is due, and the encoders do not hold too
  // many of its frames.
  bool due(Clock::time_point now) const;
  const FlowControl& flow() const { return flow_; }
  bool skips_frame(Clock::time_point now) { return flow_.skips_frame(now); }
  // What a frame shows, besides its pixels, and when its tick began.
  struct Shows {
    std::uint64_t input_event_id = 0;  // the newest of this viewer's inputs applied
    double sim_time = 0.0;
    double sim_ms = 0.0;     // the simulation's time in the tick that drew it
    double sim_speed = 0.0;  // simulated seconds per wall second (SimSpeed)
    double input_wait_ms = 0.0;
    Clock::time_point tick_start{};
    Clock::time_point submitted{};
    std::string renderer;
    // Set where it was drawn while others watched: what its session's account paid for it.
    std::optional<FrameCharge> charge;
    std::optional<std::uint64_t> probed_drag;  // the drag it read the surface back for, if any
  };
  struct Finished {
    codec::Image image;  // YCbCr 4:2:0 planes, ready for the JPEG encoder
    std::uint64_t sequence;
    Shows shows;
    render::RenderTimes times;
    double queue_ms;  // submitted to taken back
    int jpeg_quality;
  };
  // Renders into the read-back ring; the GPU copies the frame to the host while the worker goes
  // on. `shows.tick_start` is when the tick that draws it began.
  void submit(const render::ParticleView& particles, const sim::Box& tank, Shows shows,
              Clock::time_point now);
  // The oldest frame in the ring, waiting for it if need be (a tick after its submission it is
  // done).
  std::optional<Finished> take_finished(Clock::time_point now);
  // Whether take_finished() has a frame that the GPU has finished.
  bool frame_finished();
  // GPU milliseconds one of its frames costs (render passes and read-back, from timestamps).
  const CostEstimate& frame_cost() const { return frame_cost_; }
  // What a finished frame took, by the same measure.
  static double gpu_ms(const Finished& frame) {
    return frame.times.drawing_ms() + frame.times.readback_ms;
  }
  // Its frames' size as rendered, in millions of pixels.
  double megapixels() const { return double(render_width_) * double(render_height_) * 1e-6; }
  void note_input(std::uint64_t event_id, Clock::time_point received);
  std::uint64_t newest_input() const { return newest_input_; }
  // How long the newest input waited for the tick that applies it, for the first frame that shows
  // it; 0 for later frames (they wait for no input).
  double input_wait_ms(Clock::time_point tick_start);

  // Where it looks from: its camera, and the frame size it asked for.
  struct View {
    render::OrbitCamera camera;
    FlowControl::Size size;
  };
  View view() const { return {camera_, {width_, height_}}; }
  // The view of the seat it resumes: its camera, fitted to the tank again when this viewer's
  // frames are turned from those it was seen in (portrait and landscape), as a turned viewport's.
  void resume_view(const View& seen);
  // Counts frames in the encoders; the encoder's callback decrements it.
  const std::shared_ptr<std::atomic<int>>& encoding() const { return encoding_; }

 private:
  float aspect() const { return float(render_width_) / float(render_height_); }
  // The size frames are to be rendered at; the first renderer is made at once, later ones by
  // settle_size().
  void aim_size(std::uint32_t width, std::uint32_t height);
  void make_renderer(std::uint32_t width, std::uint32_t height);

  gpu::Context* context_;
  std::uint32_t id_;
  Seat seat_;
  const ServerLimits* limits_;
  std::shared_ptr<ViewerSink> sink_;
  std::unique_ptr<render::FrameRenderer> renderer_;
  std::uint32_t width_ = 0, height_ = 0;                // as asked
  std::uint32_t render_width_ = 0, render_height_ = 0;  // as rendered (adaptation may lower it)
  std::uint32_t aimed_width_ = 0, aimed_height_ = 0;    // as it will be, at settle_size()
  Clock::time_point last_resize_{};
  std::optional<FlowControl::Size> unfit_size_;  // found no GPU memory (settle_size)
  render::OrbitCamera camera_;
  render::RendererKind renderer_kind_ = render::RendererKind::automatic;
  sim::Box tank_;  // what the camera looks at
  render::OrbitLimits orbit_{0.05f, 1000.0f};
  FlowControl flow_{Clock::now()};
  Gestures gestures_{seat_.access == Access::control};
  DragProbe drag_;
  std::deque<Shows> in_flight_;  // what each frame in the renderer's ring shows
  CostEstimate frame_cost_;
  bool renderer_warm_ = false;  // its renderer has drawn a frame
  std::uint64_t newest_input_ = 0;
  Clock::time_point newest_input_received_{};
  std::uint64_t input_shown_ = 0;  // the newest input a submitted frame shows
  std::shared_ptr<std::atomic<int>> encoding_ = std::make_shared<std::atomic<int>>(0);
};

}  // namespace fluidcast::server

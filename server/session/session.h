// A session: one simulation and any number of viewers, each with its own camera, size and
// quality (DESIGN.md §1). Transports post input from their threads; everything else runs on the
// GPU worker's thread, one tick at a time. Knows nothing of gRPC or HTTP.
#pragma once

#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "fluidcast/codec/jpeg_encoder_pool.h"
#include "fluidcast/render/particle_source.h"
#include "fluidcast/sim/solver.h"
#include "server_limits.h"
#include "metrics.h"
#include "viewer.h"

namespace fluidcast::server {

struct SessionSetup {
  sim::SceneKind scene = sim::SceneKind::dam_break;
  sim::SolverKind solver = sim::SolverKind::pbf;
  std::uint32_t particles = 0;  // 0: the server's default
};

// What a session needs from the server around it.
struct SessionServices {
  gpu::Context* context;
  bool gpu_solver;  // simulate on the GPU (a hardware device) or on the CPU (lavapipe)
  const ServerLimits* limits;
  Metrics* metrics;
  codec::JpegEncoderPool* encoders;
};

class Session {
 public:
  // Throws Refusal (RESOURCE_EXHAUSTED) when the solver does not fit the device.
  Session(std::string id, SessionSetup setup, SessionServices services);
  ~Session();

  const std::string& id() const { return id_; }

  // From any thread: a validated message of a viewer's stream, applied at the next tick.
  void post(std::uint32_t viewer, v1::ClientMessage message);

  // The rest on the worker's thread.
  // Adds a viewer (resuming `resume`'s camera when that viewer left recently); returns its id.
  std::uint32_t add_viewer(const v1::Hello& hello, std::shared_ptr<ViewerSink> sink);
  // The viewer's stream ended; its camera is kept for a resume.
  void remove_viewer(std::uint32_t viewer);
  std::size_t viewer_count() const { return viewers_.size(); }
  Clock::time_point empty_since() const { return empty_since_; }
  void tick(Clock::time_point now);
  v1::SessionState state() const;
  v1::Snapshot snapshot() const;
  // Replaces the fluid; throws Refusal for a snapshot that does not fit.
  std::uint32_t load(const v1::Snapshot& snapshot);
  // Ends every viewer's stream (server shutdown).
  void end_all(const Refusal& why);

 private:
  void rebuild(SessionSetup setup);
  // Applies the newest scene, solver or count wish, or a reset, at most once per interval.
  void apply_rebuilds(Clock::time_point now);
  // Takes every frame in flight to the encoders: before the particles' buffers change (reset,
  // rebuild, load), since those frames read them.
  void finish_frames();
  void apply(Viewer& viewer, const v1::ClientMessage& message, Clock::time_point received);
  void step(Clock::time_point now);
  void encode(Viewer& viewer, Viewer::Finished frame);
  float collider_radius() const;

  std::string id_;
  SessionServices services_;
  SessionSetup setup_;
  std::unique_ptr<sim::Solver> solver_;
  render::ParticleSource source_;
  std::map<std::uint32_t, std::unique_ptr<Viewer>> viewers_;
  std::map<std::uint32_t, render::OrbitCamera> departed_;  // cameras kept for a resume
  std::uint32_t next_viewer_ = 1;
  bool paused_ = false;
  std::optional<SessionSetup> setup_wanted_;
  std::uint32_t setup_requester_ = 0;  // told when the wish cannot be met
  bool reset_wanted_ = false;
  Clock::time_point last_rebuild_{};
  Clock::time_point last_tick_{};
  double lag_seconds_ = 0.0;  // real time the simulation still owes
  Clock::time_point empty_since_;

  struct Posted {
    std::uint32_t viewer;
    v1::ClientMessage message;
    Clock::time_point received;  // acknowledgements time the round trip from here
  };
  std::mutex inbox_mutex_;
  std::vector<Posted> inbox_;
};

}  // namespace fluidcast::server

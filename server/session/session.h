// A session: one simulation and any number of viewers, each with its own camera, size and
// quality. Transports post input from their threads; everything else runs on the GPU worker's
// thread, one tick at a time: prepare() says what the tick would cost on the GPU, simulate() and
// draw() spend what the hub grants (gpu_budget.h). Knows nothing of gRPC or HTTP.
#pragma once

#include <algorithm>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "finger_strokes.h"
#include "fluidcast/codec/jpeg_encoder_pool.h"
#include "fluidcast/render/particle_source.h"
#include "fluidcast/sim/fork_join_pool.h"
#include "fluidcast/sim/gpu_step_batch.h"
#include "fluidcast/sim/solver.h"
#include "gpu_budget.h"
#include "metrics.h"
#include "server_limits.h"
#include "sim_speed.h"
#include "viewer.h"

namespace fluidcast::server {

struct SessionSetup {
  sim::SceneKind scene = sim::SceneKind::dam_break;
  sim::SolverKind solver = sim::SolverKind::pbf;
  std::uint32_t particles = 0;  // 0: the server's default

  bool operator==(const SessionSetup&) const = default;
};

// What a session needs from the server around it.
struct SessionServices {
  gpu::Context* context;
  bool gpu_solver;           // simulate on the GPU (a hardware device) or on the CPU (lavapipe)
  sim::GpuStepBatch* steps;  // where a GPU solver's steps wait for the tick's one submission
  // What a frame costs per million pixels on this device, from every session's measured frames:
  // the price of a frame whose viewer has none measured yet (a new viewer, a new size).
  CostEstimate* frame_ms_per_megapixel;
  std::shared_ptr<sim::ForkJoinPool> cpu_threads;  // what a CPU solver steps on
  const ServerLimits* limits;
  Metrics* metrics;
  codec::JpegEncoderPool* encoders;
};

class Session {
 public:
  // Throws Refusal (RESOURCE_EXHAUSTED) when the solver does not fit the device. `creator`: the
  // address of the client that created it (its sessions count against the per-address limit).
  Session(std::string id, std::string creator, SessionSetup setup, SessionServices services);
  // A session that goes on from a state handed back (NewSession.state): its scene, solver and
  // count. Throws Refusal for a state that does not fit, its particles checked before any solver
  // is built.
  Session(std::string id, std::string creator, const v1::Snapshot& state, SessionServices services);
  ~Session();

  const std::string& id() const { return id_; }
  const std::string& creator() const { return creator_; }
  const SessionKeys& keys() const { return keys_; }

  // From any thread: a validated message of a viewer's stream, applied at the next tick.
  void post(std::uint32_t viewer, v1::ClientMessage message);

  // The rest, and the destructor, on the worker's thread.
  // Adds a viewer that may do what `access` allows; returns its id. A Hello.resume that falls
  // back to its session_key (the viewer forgotten) joins here too, taking its state on
  // resume_viewer's terms.
  std::uint32_t add_viewer(const v1::Hello& hello, std::shared_ptr<ViewerSink> sink, Access access);
  // The viewer, connected or recently departed, whose resume key `key` is.
  std::optional<std::uint32_t> viewer_resumed_by(const std::string& key) const;
  // A new connection for viewer `resumed` (viewer_resumed_by): its camera and access, a new
  // resume key, and the fluid in Hello.resume.state if any; a connection it still has is ended.
  // A Refusal (no room, no GPU memory for its frames, a state that does not fit) changes nothing:
  // the viewer stays as it was, connected or departed. Returns the new viewer's id.
  std::uint32_t resume_viewer(const v1::Hello& hello, std::shared_ptr<ViewerSink> sink,
                              std::uint32_t resumed);
  // What the viewer may do.
  Access access(std::uint32_t viewer) const;
  // What Welcome.access tells the viewer: its access and the keys it may share or resume with.
  v1::Access access_message(std::uint32_t viewer) const;
  // The viewer's stream ended. One that dropped (or was ended by the server) is kept for a resume
  // within the grace period; one that said goodbye cannot come back.
  void remove_viewer(std::uint32_t viewer, Departure departure = Departure::dropped);
  std::size_t viewer_count() const { return viewers_.size(); }
  // Nobody watches and nobody who dropped may still resume: the session can end.
  bool expired(Clock::time_point now) const;
  // GPU time it spent beyond its grants (its accounts below zero), which its client owes: handed
  // to the client's ledger (ClientDebts) once it has no viewers, its accounts left at zero; and,
  // at its start, what its client owes from earlier sessions.
  struct Debts {
    double sim_ms = 0.0, render_ms = 0.0;
  };
  Debts hand_over_debts();
  void inherit_debts(const Debts& debts);
  // GPU milliseconds a frame of `viewer` would cost: its own estimate, else the device's per
  // pixel; nothing when neither is known yet (the frame is drawn to be measured).
  std::optional<double> frame_price(const Viewer& viewer) const;
  // When a viewer last joined, touched, commanded, or tilted by more than kIdleTiltDegrees.
  Clock::time_point last_input() const { return last_input_; }
  // A tick in three parts: the inputs and rebuilds that arrived, and what the tick would cost
  // (the substeps real time owes, the frames due, at their measured GPU costs)...
  GpuDemand prepare(Clock::time_point now);
  // ...then the steps that the grant pays for (a GPU solver's wait in services.steps, which the
  // hub submits once every session has queued its own)...
  void simulate(const GpuGrant& grant);
  // ...and the frames it pays for, which draw those steps. The frames of the previous tick are
  // taken to the encoders first (waiting for them if need be).
  void draw(const GpuGrant& grant, Clock::time_point now);
  // Takes frames in flight to the encoders: every one, waiting for the GPU if need be (draw()
  // does, before new frames reuse the read-back ring), or only those the GPU has finished
  // (between ticks, so that a frame is sent as soon as it is drawn).
  enum class FrameWait { for_all, finished_only };
  void send_frames(FrameWait wait);
  // For /metrics.
  SessionFigures figures() const;
  v1::SessionState state() const;
  // The fluid's state, its read-out charged to this session as a load is (GetSnapshot, a state
  // request): a client that keeps asking slows its own fluid, not the others'.
  v1::Snapshot snapshot();
  // Replaces the fluid, as the snapshot's scene, solver and count (a fluid of another is spaced
  // otherwise: it is rebuilt for them); throws Refusal for a snapshot that does not fit, and the
  // session keeps its fluid.
  std::uint32_t load(const v1::Snapshot& snapshot);
  // Ends every viewer's stream (shutdown, idle timeout); each may resume while the session lives.
  void end_all(const Refusal& why);
  // Ends every viewer's stream and the session with them (it failed): nobody resumes or joins it,
  // and it expires at once. A session left in an unknown state would fail its viewers again.
  void end_for_good(const Refusal& why);
  bool failed() const { return failed_; }

 private:
  // Without a fluid yet: the public constructors give it one.
  Session(std::string id, std::string creator, SessionServices services);
  // load()'s work, charged by it; the first fluid too, where there is no solver yet.
  std::uint32_t replace_fluid(const v1::Snapshot& snapshot);
  // Throws a Refusal when the session has its most viewers, `leaving` of them about to go.
  void check_room(std::size_t leaving) const;
  // A viewer, its frames' GPU memory taken (a Refusal when there is none), not yet seated.
  std::unique_ptr<Viewer> new_viewer(const v1::Hello& hello, std::shared_ptr<ViewerSink> sink,
                                     Seat seat);
  // Returns its id.
  std::uint32_t seat_viewer(std::unique_ptr<Viewer> viewer);
  void rebuild(SessionSetup setup);
  // The scene `setup` starts from (its count filled in with the server's default where it names
  // none), under the session's gravity; throws a Refusal naming what cannot be had.
  sim::Scene scene_for(SessionSetup& setup) const;
  sim::SolverParams solver_params() const;
  // A solver of `setup`'s kind for `scene`; throws a Refusal naming what cannot be had. The
  // session's own fluid is untouched.
  std::unique_ptr<sim::Solver> build_solver(const SessionSetup& setup, sim::Scene scene) const;
  // Makes `solver`, built for `setup`, the session's fluid, and tells the viewers.
  void adopt(std::unique_ptr<sim::Solver> solver, const SessionSetup& setup);
  // Tells every viewer the session's state (ServerMessage.session): it may have changed, or a
  // viewer may show a change it asked for that did not come (a client's menu does at once).
  void tell_state();
  // Hands `solver` to the context, to be destroyed after the frames that read its particles.
  void retire_solver(std::unique_ptr<sim::Solver> solver);
  // Applies the newest scene, solver or count wish, or a reset, at most once per interval and
  // not while the time of the last one is still being repaid.
  void apply_rebuilds(Clock::time_point now);
  void rebuild_or_reset();
  void apply(Viewer& viewer, const v1::ClientMessage& message, Clock::time_point received);
  void apply_tilt(Viewer& viewer, const v1::Tilt& tilt, Clock::time_point received);
  void answer_state_request(Viewer& viewer);
  void apply_command(Viewer& viewer, const v1::Command& command);
  // Submits the due frames that the grant pays for (all of them when no other session is
  // watched; the floors aside), each charged its price now and settled against its timestamps
  // when it finishes (send_frames).
  void render(const GpuGrant& grant, Clock::time_point now);
  // A new fluid (rebuild, loaded snapshot): its costs are measured afresh; what the session owes
  // stays owed.
  void forget_costs();
  // Work done on the worker outside any grant (a rebuild, a state put in), begun at `started`:
  // while other sessions are watched, charged to this session's simulation, so that a client
  // that keeps asking slows its own fluid, not the others'.
  void charge_worker_time(Clock::time_point started);
  // Counts the cost of finished steps into substep_cost_ and measured_sim_ms_.
  void measure_steps(double ms, std::uint64_t substeps);
  void encode(Viewer& viewer, Viewer::Finished frame);
  float collider_radius() const;
  // The fingers' spheres for a tick that simulates `seconds` of the `elapsed` wall seconds since
  // the last (sim::FingerCollider): each moves from where the fluid last had it towards its
  // finger, in simulated time never faster than the hand moved in wall time, and a lifted
  // finger's on to where the finger was last, beside a next stroke of the same viewer's
  // (FingerStrokes). A fluid in slow motion sees the finger in slow motion too.
  void move_colliders(double seconds, double elapsed);

  std::string id_;
  std::string creator_;
  SessionKeys keys_;
  SessionServices services_;
  SessionSetup setup_;
  std::unique_ptr<sim::Solver> solver_;
  render::ParticleSource source_;
  std::map<std::uint32_t, std::unique_ptr<Viewer>> viewers_;
  // Kept for a resume.
  struct Departed {
    Viewer::View view;
    Seat seat;
    Clock::time_point left;
  };
  std::map<std::uint32_t, Departed> departed_;
  std::uint32_t next_viewer_ = 1;
  bool paused_ = false;
  bool failed_ = false;
  std::optional<SessionSetup> setup_wanted_;
  // The viewer that asked for each part of the wish (0: none), told when its part cannot be met.
  struct WishAskers {
    std::uint32_t scene = 0, solver = 0, particles = 0;
  };
  WishAskers wish_askers_;
  bool reset_wanted_ = false;
  Clock::time_point last_rebuild_{};
  Clock::time_point last_tick_{};
  double tick_elapsed_ = 0.0;  // wall seconds since the tick before
  double lag_seconds_ = 0.0;   // real time the simulation still owes
  GpuAccount sim_account_, render_account_;
  Clock::time_point last_drawn_in_debt_{};  // the last frame drawn whatever the debt
  bool contended_ = false;                  // other sessions were watched at the last grant
  CostEstimate substep_cost_;     // ms of one substep (GPU time, or CPU time for a CPU solver)
  double measured_sim_ms_ = 0.0;  // the steps measured since the last frame was submitted
  SimSpeed speed_;
  FingerStrokes fingers_;  // the dragging viewers' spheres, and the strokes still finishing
  Clock::time_point last_input_ = Clock::now();
  glm::vec3 last_active_tilt_{0.0f, -1.0f, 0.0f};  // the last tilt that counted as input

  struct Posted {
    std::uint32_t viewer;
    v1::ClientMessage message;
    Clock::time_point received;  // acknowledgements time the round trip from here
  };
  std::mutex inbox_mutex_;
  std::vector<Posted> inbox_;
};

}  // namespace fluidcast::server

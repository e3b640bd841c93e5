#include "session.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "fluidcast/gpu/vk_check.h"
#include "fluidcast/render/frame_renderer.h"
#include "fluidcast/sim/param_spec.h"
#include "fluidcast/sim/scene.h"
#include "frame_admission.h"
#include "input_rules.h"

namespace fluidcast::server {
namespace {

// Resets and scene, solver and count changes rebuild the simulation: at most one per this
// interval, the newest wish winning, so no client can keep the worker busy rebuilding.
constexpr auto kRebuildInterval = std::chrono::milliseconds(500);
// Time steps of real time the simulation may owe; past it the fluid runs slow instead.
constexpr double kMaxOwedSteps = 4.0;
// Frames smaller than this (a 320×240 frame is 0.077) do not set the device's price per pixel.
constexpr double kLeastPricedMegapixels = 0.05;

double milliseconds(Clock::duration duration) {
  return std::chrono::duration<double, std::milli>(duration).count();
}

double milliseconds_between(Clock::time_point from, Clock::time_point to) {
  return milliseconds(to - from);
}

// A simulation parameter as a client reads it: the field of its message where a client chose it,
// the scene's tank (the same size for every count: no setting of anyone's), else the server's own
// setting (the operator's).
std::string setup_field_or_setting(std::string_view name) {
  if (name == "particles") {
    return "the particle count (NewSession.particles, Command.particles, a Snapshot's particles)";
  }
  if (name == "scene") return "the scene (NewSession.scene, Command.scene, Snapshot.scene)";
  if (name == "solver") return "the solver (NewSession.solver, Command.solver, Snapshot.solver)";
  if (name == "tank-length") return "the scene's tank length (fixed)";
  if (name == "tank-height") return "the scene's tank height (fixed)";
  if (name == "depth") return "the scene's tank depth (fixed)";
  return "the server's " + std::string(name);
}

// The fluid a Hello.resume hands back, if any (null when none); PERMISSION_DENIED for a seat
// with the view key's `access`, before anything changes.
const v1::Snapshot* handed_back(const v1::Hello& hello, Access access) {
  if (!hello.has_resume() || !hello.resume().has_state()) return nullptr;
  if (access != Access::control) {
    throw Refusal(RefusalCode::permission_denied,
                  "Hello.resume.state: this viewer joined with the session's view key; handing a "
                  "fluid back needs its control key");
  }
  return &hello.resume().state();
}

}  // namespace

Session::Session(std::string id, std::string creator, SessionServices services)
    : id_(std::move(id)),
      creator_(std::move(creator)),
      services_(services),
      source_(*services.context) {}

Session::Session(std::string id, std::string creator, SessionSetup setup, SessionServices services)
    : Session(std::move(id), std::move(creator), services) {
  rebuild(setup);
}

Session::Session(std::string id, std::string creator, const v1::Snapshot& state,
                 SessionServices services)
    : Session(std::move(id), std::move(creator), services) {
  load(state);
}

Session::~Session() {
  try {
    if (solver_) retire_solver(std::move(solver_));
  } catch (const std::exception&) {
    // The steps could not be submitted (a lost device, no memory to record with): the solver
    // goes with the session, rather than be retired while steps it queued wait.
  }
}

void Session::retire_solver(std::unique_ptr<sim::Solver> solver) {
  // Frames in flight still read its particles; steps it queued go first, so that none is recorded
  // after it is retired (gpu_step_batch.h).
  services_.steps->submit();
  services_.context->retire(std::move(solver));
}

void Session::send_frames(FrameWait wait) {
  for (auto& [id, viewer] : viewers_) {
    while (wait == FrameWait::for_all || viewer->frame_finished()) {
      auto finished = viewer->take_finished(Clock::now());
      if (!finished) break;
      if (finished->shows.charge) {
        render_account_.spend(finished->shows.charge->settle(Viewer::gpu_ms(*finished)));
      }
      // Tiny frames cost mostly what any frame costs: they would overprice the pixels.
      if (viewer->frame_cost().known() && viewer->megapixels() >= kLeastPricedMegapixels) {
        services_.frame_ms_per_megapixel->add(viewer->frame_cost().ms() / viewer->megapixels());
      }
      encode(*viewer, std::move(*finished));
    }
  }
}

void Session::forget_costs() {
  lag_seconds_ = 0.0;
  substep_cost_ = {};
  sim_account_.forget_credit();
}

void Session::charge_worker_time(Clock::time_point started) {
  if (contended_) sim_account_.spend(milliseconds_between(started, Clock::now()));
}

SessionFigures Session::figures() const {
  SessionFigures figures;
  figures.sim_speed = speed_.speed();
  figures.substep_ms = substep_cost_.ms();
  for (const auto& [id, viewer] : viewers_) figures.frame_ms += viewer->frame_cost().ms();
  figures.particles = solver_->particle_count();
  return figures;
}

void Session::rebuild(SessionSetup setup) {
  sim::Scene scene = scene_for(setup);
  adopt(build_solver(setup, std::move(scene)), setup);
  for (auto& [id, viewer] : viewers_) viewer->look_at(solver_->tank());
}

sim::Scene Session::scene_for(SessionSetup& setup) const {
  if (setup.particles == 0) setup.particles = services_.limits->default_particles;
  sim::SceneParams params;
  params.kind = setup.scene;
  params.particles = static_cast<int>(setup.particles);
  try {
    sim::Scene scene = sim::build_scene(params);
    // A fluid rebuilt while a viewer holds the tank tilted falls as the old one did.
    if (solver_) scene.gravity = solver_->gravity();
    return scene;
  } catch (const sim::ParamError& e) {
    throw Refusal(RefusalCode::resource_exhausted, e.worded(setup_field_or_setting));
  }
}

sim::SolverParams Session::solver_params() const {
  sim::SolverParams params;
  params.max_particles = static_cast<int>(services_.limits->max_particles);
  return params;
}

std::unique_ptr<sim::Solver> Session::build_solver(const SessionSetup& setup,
                                                   sim::Scene scene) const {
  try {
    return services_.gpu_solver
               ? sim::make_gpu_solver(setup.solver, *services_.context, std::move(scene),
                                      solver_params(), services_.steps)
               : sim::make_cpu_solver(setup.solver, std::move(scene), solver_params(),
                                      services_.cpu_threads);
  } catch (const sim::ParamError& e) {
    throw Refusal(RefusalCode::resource_exhausted, e.worded(setup_field_or_setting));
  } catch (const gpu::VulkanError& e) {  // within the budget, but other sessions hold the memory
    if (!e.out_of_memory()) throw;
    throw no_gpu_memory(setup_field_or_setting("particles"),
                        std::to_string(setup.particles) + " particles", e,
                        "ask for fewer, or later");
  }
}

void Session::adopt(std::unique_ptr<sim::Solver> solver, const SessionSetup& setup) {
  if (solver_) {
    retire_solver(std::exchange(solver_, std::move(solver)));
  } else {
    solver_ = std::move(solver);
  }
  setup_ = setup;
  forget_costs();    // another count or solver: another cost
  fingers_.clear();  // the fingers' spheres grow into the new fluid afresh
  tell_state();
}

void Session::tell_state() {
  auto message = std::make_shared<v1::ServerMessage>();
  *message->mutable_session() = state();
  for (auto& [id, viewer] : viewers_) viewer->sink().deliver(message);
}

std::uint32_t Session::add_viewer(const v1::Hello& hello, std::shared_ptr<ViewerSink> sink,
                                  Access access) {
  const v1::Snapshot* state = handed_back(hello, access);
  check_room(0);
  std::unique_ptr<Viewer> viewer = new_viewer(hello, std::move(sink), Seat{access});
  if (state) load(*state);
  return seat_viewer(std::move(viewer));
}

std::optional<std::uint32_t> Session::viewer_resumed_by(const std::string& key) const {
  std::optional<std::uint32_t> found;
  // Every key compared, the right one or not: how long it takes tells nothing.
  for (const auto& [id, viewer] : viewers_) {
    if (same_key(key, viewer->seat().resume_key)) found = id;
  }
  const auto now = Clock::now();
  for (const auto& [id, departed] : departed_) {
    const bool in_grace = now - departed.left <= services_.limits->resume_grace;
    if (same_key(key, departed.seat.resume_key) && in_grace) found = id;
  }
  return found;
}

std::uint32_t Session::resume_viewer(const v1::Hello& hello, std::shared_ptr<ViewerSink> sink,
                                     std::uint32_t resumed) {
  const auto live = viewers_.find(resumed);
  const auto kept = departed_.find(resumed);
  const bool connected = live != viewers_.end();
  if (!connected && kept == departed_.end()) {
    throw Refusal(RefusalCode::not_found, "Hello.resume.key: that viewer has been forgotten");
  }
  const Access access = connected ? live->second->seat().access : kept->second.seat.access;
  const v1::Snapshot* state = handed_back(hello, access);
  // Whatever may refuse comes before anything changes (a room, the new connection's frames in GPU
  // memory, the state): a refusal leaves the viewer as it was, connected or free to resume. A new
  // resume key each time: one that leaked brings back no one after its viewer's next connection.
  check_room(connected ? 1 : 0);
  std::unique_ptr<Viewer> viewer = new_viewer(hello, std::move(sink), Seat{access});
  viewer->resume_view(connected ? live->second->view() : kept->second.view);
  if (state) load(*state);
  if (connected) {
    // The old connection may not be known dead yet (a phone that changed networks): the resume
    // replaces it.
    live->second->sink().end(
        Refusal(RefusalCode::unavailable, "another connection resumed this viewer"));
    remove_viewer(resumed, Departure::left);
  } else {
    departed_.erase(kept);
  }
  return seat_viewer(std::move(viewer));
}

void Session::check_room(std::size_t leaving) const {
  if (viewers_.size() - leaving >= services_.limits->max_viewers_per_session) {
    throw Refusal(RefusalCode::resource_exhausted,
                  "session " + id_ + " has its limit of " +
                      std::to_string(services_.limits->max_viewers_per_session) + " viewers");
  }
}

std::unique_ptr<Viewer> Session::new_viewer(const v1::Hello& hello,
                                            std::shared_ptr<ViewerSink> sink, Seat seat) {
  auto viewer = std::make_unique<Viewer>(*services_.context, next_viewer_++, std::move(seat),
                                         hello.viewport(), hello.quality(), *services_.limits,
                                         std::move(sink));
  viewer->look_at(solver_->tank());
  return viewer;
}

std::uint32_t Session::seat_viewer(std::unique_ptr<Viewer> viewer) {
  const std::uint32_t id = viewer->id();
  viewers_.emplace(id, std::move(viewer));
  services_.metrics->viewers++;
  last_input_ = Clock::now();
  return id;
}

Access Session::access(std::uint32_t viewer) const { return viewers_.at(viewer)->seat().access; }

v1::Access Session::access_message(std::uint32_t viewer) const {
  const Seat& seat = viewers_.at(viewer)->seat();
  v1::Access access;
  access.set_control(seat.access == Access::control);
  access.set_view_key(keys_.view);
  if (seat.access == Access::control) access.set_control_key(keys_.control);
  access.set_resume_key(seat.resume_key);
  return access;
}

void Session::remove_viewer(std::uint32_t id, Departure departure) {
  const auto found = viewers_.find(id);
  if (found == viewers_.end()) return;
  if (departure == Departure::dropped) {
    const auto now = Clock::now();
    departed_[id] = {found->second->view(), found->second->seat(), now};
    // Past the grace a viewer can no longer resume its own seat; beyond the limit, those who
    // left earliest are forgotten first (not those who joined earliest: the creator, connected
    // for hours, may be the one whose network just changed).
    std::erase_if(departed_, [&](const auto& departed) {
      return now - departed.second.left > services_.limits->resume_grace;
    });
    while (departed_.size() > kMaxDepartedViewers) {
      departed_.erase(std::min_element(
          departed_.begin(), departed_.end(),
          [](const auto& a, const auto& b) { return a.second.left < b.second.left; }));
    }
  }
  viewers_.erase(found);
  services_.metrics->viewers--;
}

std::optional<double> Session::frame_price(const Viewer& viewer) const {
  if (viewer.frame_cost().known()) return viewer.frame_cost().ms();
  if (services_.frame_ms_per_megapixel->known()) {
    return services_.frame_ms_per_megapixel->ms() * viewer.megapixels();
  }
  return std::nullopt;
}

Session::Debts Session::hand_over_debts() {
  const Debts debts{std::max(0.0, -sim_account_.balance_ms()),
                    std::max(0.0, -render_account_.balance_ms())};
  inherit_debts({-debts.sim_ms, -debts.render_ms});  // back to zero
  return debts;
}

void Session::inherit_debts(const Debts& debts) {
  sim_account_.spend(debts.sim_ms);
  render_account_.spend(debts.render_ms);
}

bool Session::expired(Clock::time_point now) const {
  if (!viewers_.empty()) return false;
  const auto grace = services_.limits->resume_grace;
  return std::none_of(departed_.begin(), departed_.end(),
                      [&](const auto& departed) { return now - departed.second.left <= grace; });
}

void Session::end_all(const Refusal& why) {
  while (!viewers_.empty()) {
    const auto first = viewers_.begin();
    first->second->sink().end(why);
    remove_viewer(first->first);  // kept for a resume (after an idle timeout, say)
  }
}

void Session::end_for_good(const Refusal& why) {
  failed_ = true;
  end_all(why);
  departed_.clear();
}

float Session::collider_radius() const { return std::max(0.04f, 4.0f * solver_->scene().spacing); }

void Session::move_colliders(double seconds, double elapsed) {
  // Live drags first: FingerStrokes keeps the first under the solver's cap.
  std::vector<FingerStrokes::Finger> fingers, ended;
  for (auto& [id, viewer] : viewers_) {
    const DragProbe::Points points = viewer->drag_points();
    if (points.live) fingers.push_back({id, points.live->drag, points.live->point});
    for (const DragProbe::DragPoint& finger : points.ended) {
      ended.push_back({id, finger.drag, finger.point});
    }
  }
  fingers.insert(fingers.end(), ended.begin(), ended.end());
  solver_->set_colliders(fingers_.move(fingers, seconds, elapsed, collider_radius()));
}

void Session::apply_rebuilds(Clock::time_point now) {
  if ((!setup_wanted_ && !reset_wanted_) || now - last_rebuild_ < kRebuildInterval) return;
  // A rebuild runs on the worker, outside any grant. While other sessions are watched, its time
  // is charged to this session's simulation and the next waits until that is repaid: a client
  // that keeps asking slows its own fluid, not the others'.
  if (contended_ && sim_account_.balance_ms() < 0.0) return;
  last_rebuild_ = now;
  const auto started = Clock::now();
  rebuild_or_reset();
  charge_worker_time(started);
}

void Session::rebuild_or_reset() {
  if (setup_wanted_) {
    SessionSetup wanted = *std::exchange(setup_wanted_, std::nullopt);
    const WishAskers askers = std::exchange(wish_askers_, {});
    reset_wanted_ = false;
    // What does not fit the GPU (the count, else the solver, else the scene) is refused to the
    // viewer that asked for it, and the rest of the wish, other viewers' perhaps, is tried again;
    // with nothing left, the old fluid stays.
    for (;;) {
      try {
        rebuild(wanted);
        return;
      } catch (const Refusal& refusal) {
        // A rebuild to the fluid it has (a wish for what it is) blames whoever asked.
        std::uint32_t asker = askers.scene    ? askers.scene
                              : askers.solver ? askers.solver
                                              : askers.particles;
        if (wanted.particles != setup_.particles) {
          asker = askers.particles;
          wanted.particles = setup_.particles;
        } else if (wanted.solver != setup_.solver) {
          asker = askers.solver;
          wanted.solver = setup_.solver;
        } else {
          wanted.scene = setup_.scene;
        }
        if (const auto asked = viewers_.find(asker); asked != viewers_.end()) {
          asked->second->sink().end(refusal);
          remove_viewer(asker);
        }
        if (wanted == setup_) return;
      }
    }
  } else {
    reset_wanted_ = false;
    try {
      solver_->reset();
    } catch (const gpu::VulkanError& e) {
      // No GPU memory for the reset's upload (other sessions hold it, or --gpu-memory is met):
      // the fluid goes on as it was, which the frames show, and the session with it.
      if (!e.out_of_memory()) throw;
      spdlog::warn("session {}: the fluid was not reset: {}", id_, e.what());
      return;
    }
    fingers_.clear();
  }
}

GpuDemand Session::prepare(Clock::time_point now) {
  std::vector<Posted> inbox;
  {
    std::lock_guard lock(inbox_mutex_);
    inbox.swap(inbox_);
  }
  for (auto& [id, message, received] : inbox) {
    const auto found = viewers_.find(id);
    if (found == viewers_.end()) continue;  // its stream ended meanwhile
    try {
      apply(*found->second, message, received);
    } catch (const Refusal& refusal) {
      found->second->sink().end(refusal);
      remove_viewer(id);
    } catch (const sim::ParamError& e) {
      found->second->sink().end(
          Refusal(RefusalCode::invalid_argument, e.worded(setup_field_or_setting)));
      remove_viewer(id);
    } catch (const std::invalid_argument& e) {
      found->second->sink().end(Refusal(RefusalCode::invalid_argument, e.what()));
      remove_viewer(id);
    }
  }
  apply_rebuilds(now);

  const float dt = solver_->params().time_step;
  const double elapsed = last_tick_ == Clock::time_point{}
                             ? dt
                             : std::chrono::duration<double>(now - last_tick_).count();
  last_tick_ = now;
  tick_elapsed_ = elapsed;

  GpuDemand demand;
  demand.client = creator_;
  demand.watched = !viewers_.empty();
  demand.sim_on_gpu = services_.gpu_solver;
  // Nobody watching: the fluid waits as it is, for a resume.
  const bool running = !paused_ && !viewers_.empty();
  speed_.record(now, solver_->time(), running);
  if (running) {
    lag_seconds_ = std::min(lag_seconds_ + elapsed, kMaxOwedSteps * double(dt));
    const double steps = std::floor(lag_seconds_ / dt);
    demand.sim_ms = steps * solver_->substeps_for(dt) * substep_cost_.ms();
  }
  for (auto& [id, viewer] : viewers_) {
    if (viewer->due(now)) demand.render_ms += frame_price(*viewer).value_or(0.0);
  }
  return demand;
}

void Session::measure_steps(double ms, std::uint64_t substeps) {
  if (substeps == 0) return;
  substep_cost_.add(ms / double(substeps));
  measured_sim_ms_ += ms;
  services_.metrics->sim_time.observe_ms(ms);
}

void Session::simulate(const GpuGrant& grant) {
  contended_ = grant.contended();
  // A GPU solver's steps are measured by its timestamps once they have finished; a CPU solver's
  // by the clock around them, whole (its stage timers leave out the pool's waits).
  solver_->count_finished_steps();
  if (services_.gpu_solver) {
    measure_steps(solver_->stage_times().total_ms(), solver_->stage_times().substeps);
  }
  solver_->clear_stage_times();
  if (paused_ || viewers_.empty()) {
    move_colliders(0.0, tick_elapsed_);
    return;
  }
  // Until the first steps are measured, one substep a tick; then what the account pays for.
  const bool costed = substep_cost_.known();
  const double substep_charge = grant.charge(substep_cost_.ms());
  sim_account_.deposit(grant.sim_ms, substep_charge);
  int substeps_left = costed ? sim_account_.affordable(substep_charge) : 1;
  // Whole steps only, as real time owes them; in slow motion a step of fewer substeps of the
  // same length. Never shorter substeps: PBF turns a position correction into a velocity by
  // dividing by the substep, and a sliver of one throws the fluid apart.
  const float step = solver_->params().time_step;
  struct PlannedStep {
    float seconds;
    int substeps;
  };
  std::vector<PlannedStep> plan;
  double planned = 0.0;
  const int full_step_substeps = solver_->substeps_for(step);
  while (lag_seconds_ - planned >= step && substeps_left > 0) {
    float seconds = step;
    int substeps = full_step_substeps;
    if (substeps > substeps_left) {
      seconds *= float(substeps_left) / float(substeps);
      substeps = substeps_left;
    }
    plan.push_back({seconds, substeps});
    planned += seconds;
    substeps_left -= substeps;
    if (costed) sim_account_.spend(substeps * substep_charge);
  }
  move_colliders(planned, tick_elapsed_);
  const auto started = Clock::now();
  int taken = 0;  // the CPU SPH solver may take more substeps than planned
  for (const PlannedStep& planned_step : plan)
    taken += solver_->step(planned_step.seconds, planned_step.substeps);
  lag_seconds_ -= planned;
  if (!services_.gpu_solver) {
    measure_steps(milliseconds_between(started, Clock::now()), static_cast<std::uint64_t>(taken));
  }
}

void Session::render(const GpuGrant& grant, Clock::time_point now) {
  // New sizes first, so that each frame is priced at the size it is drawn at. A new renderer's
  // time is the session's: while others are watched it is repaid before this session's next
  // frames, so resizing slows only its own viewers.
  for (auto& [id, viewer] : viewers_) {
    const auto resizing = Clock::now();
    if (viewer->due(now) && viewer->settle_size(now) && grant.contended()) {
      render_account_.spend(milliseconds_between(resizing, Clock::now()));
    }
  }
  double dearest_frame = 0.0;
  for (auto& [id, viewer] : viewers_) {
    dearest_frame = std::max(dearest_frame, grant.charge(frame_price(*viewer).value_or(0.0)));
  }
  render_account_.deposit(grant.render_ms, dearest_frame);
  struct Due {
    std::uint32_t id;
    Viewer* viewer;
    std::optional<FrameCharge> charge;
  };
  std::vector<Due> candidates;
  std::vector<DueFrame> due_frames;
  for (auto& [id, viewer] : viewers_) {
    if (viewer->due(now)) {
      candidates.push_back({id, viewer.get(), std::nullopt});
      due_frames.push_back(
          {frame_price(*viewer), milliseconds(viewer->flow().since_rendered(now))});
    } else if (viewer->skips_frame(now)) {
      services_.metrics->frames_skipped++;
    }
  }
  const FrameAdmission admission = admit_frames(grant, render_account_, due_frames,
                                                milliseconds_between(last_drawn_in_debt_, now));
  if (admission.drew_in_debt) last_drawn_in_debt_ = now;
  std::vector<Due> due;
  for (std::size_t k = 0; k < candidates.size(); ++k) {
    const FrameAdmission::Frame& frame = admission.frames[k];
    if (!frame.drawn) {
      services_.metrics->frames_deferred++;  // its share of the GPU is spent; others go first
      continue;
    }
    if (frame.on_floor) services_.metrics->frames_on_floor++;
    due.push_back({candidates[k].id, candidates[k].viewer, frame.charge});
  }
  if (due.empty()) return;  // no upload of a CPU solver's particles for nobody
  const render::ParticleView particles = source_.view_of(*solver_);
  std::vector<std::uint32_t> failed;
  for (auto& [id, viewer, charge] : due) {
    Viewer::Shows shows;
    shows.charge = charge;
    shows.input_event_id = viewer->newest_input();
    shows.sim_time = solver_->time();
    shows.sim_ms = measured_sim_ms_;
    shows.sim_speed = speed_.speed();
    shows.input_wait_ms = viewer->input_wait_ms(now);
    shows.tick_start = now;
    try {
      viewer->submit(particles, solver_->tank(), std::move(shows), now);
    } catch (const std::invalid_argument& e) {  // this viewer's choice the device cannot draw
      viewer->sink().end(Refusal(RefusalCode::failed_precondition, e.what()));
      failed.push_back(id);
    } catch (const Refusal& refusal) {  // no GPU memory for its frames
      viewer->sink().end(refusal);
      failed.push_back(id);
    }
  }
  for (std::uint32_t id : failed) remove_viewer(id);
  measured_sim_ms_ = 0.0;
}

void Session::draw(const GpuGrant& grant, Clock::time_point now) {
  // The steps were submitted first: they run while the GPU still draws last tick's frames (which
  // read uploaded or GPU-side particles; the queue orders them), then those frames go to the
  // encoders.
  send_frames(FrameWait::for_all);
  render(grant, now);
}

void Session::encode(Viewer& viewer, Viewer::Finished frame) {
  Metrics& metrics = *services_.metrics;
  metrics.render_time.observe_ms(frame.times.drawing_ms());
  metrics.readback_time.observe_ms(frame.times.readback_ms);
  metrics.input_wait_time.observe_ms(frame.shows.input_wait_ms);
  metrics.queue_time.observe_ms(frame.queue_ms);
  auto message = std::make_shared<v1::ServerMessage>();
  v1::Frame& out = *message->mutable_frame();
  out.set_sequence(frame.sequence);
  out.set_sim_time(frame.shows.sim_time);
  out.set_width(static_cast<std::uint32_t>(codec::width_of(frame.image)));
  out.set_height(static_cast<std::uint32_t>(codec::height_of(frame.image)));
  out.set_input_event_id(frame.shows.input_event_id);
  out.set_jpeg_quality(static_cast<std::uint32_t>(frame.jpeg_quality));
  out.set_renderer(frame.shows.renderer);
  out.set_sim_speed(static_cast<float>(frame.shows.sim_speed));
  v1::StageTimings& timings = *out.mutable_timings();
  timings.set_sim_ms(static_cast<float>(frame.shows.sim_ms));
  timings.set_render_ms(static_cast<float>(frame.times.drawing_ms()));
  timings.set_readback_ms(static_cast<float>(frame.times.readback_ms));
  timings.set_input_wait_ms(static_cast<float>(frame.shows.input_wait_ms));
  timings.set_queue_ms(static_cast<float>(frame.queue_ms));
  codec::JpegOptions options;
  options.quality = frame.jpeg_quality;
  ++*viewer.encoding();
  services_.encoders->encode(
      std::move(frame.image), options,
      [message, sink = viewer.shared_sink(), metrics = services_.metrics,
       encoding = viewer.encoding(), tick_start = frame.shows.tick_start, handed = Clock::now()](
          std::vector<std::uint8_t> jpeg, double milliseconds, std::exception_ptr error) {
        --*encoding;
        if (error) return;  // options are ours and valid; nothing a client could fix
        const auto done = Clock::now();
        const double encode_wait_ms =
            std::max(0.0, milliseconds_between(handed, done) - milliseconds);
        const double server_ms = milliseconds_between(tick_start, done);
        v1::StageTimings& stages = *message->mutable_frame()->mutable_timings();
        stages.set_encode_ms(static_cast<float>(milliseconds));
        stages.set_encode_wait_ms(static_cast<float>(encode_wait_ms));
        stages.set_server_ms(static_cast<float>(server_ms));
        metrics->encode_time.observe_ms(milliseconds);
        metrics->encode_wait_time.observe_ms(encode_wait_ms);
        metrics->server_time.observe_ms(server_ms);
        v1::Frame& encoded = *message->mutable_frame();
        metrics->bytes_sent += jpeg.size();
        encoded.set_jpeg(jpeg.data(), jpeg.size());
        metrics->frames_sent++;
        if (!sink->deliver(message)) metrics->frames_dropped++;
      });
}

}  // namespace fluidcast::server

#include "session_hub.h"

#include <malloc.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <new>
#include <set>
#include <string_view>

#include "fluidcast/gpu/vk_check.h"
#include "fluidcast/render/frame_renderer.h"
#include "fluidcast/sim/scene.h"
#include "fluidcast/version.h"
#include "input_rules.h"

namespace fluidcast::server {
namespace {

// A failure of the server's while serving a request (`doing`): out of GPU memory (other sessions
// hold it, or --gpu-memory is met) is RESOURCE_EXHAUSTED, the request having asked for more than
// there is; anything else (a lost device) is INTERNAL.
Refusal server_failure(const std::exception& e, const std::string& doing) {
  const auto* vulkan = dynamic_cast<const gpu::VulkanError*>(&e);
  if (vulkan && vulkan->out_of_memory()) {
    return no_gpu_memory(doing, "it", e, "fewer particles or smaller frames need less");
  }
  if (dynamic_cast<const std::bad_alloc*>(&e)) {
    return Refusal(RefusalCode::resource_exhausted,
                   doing + ": the server has no memory for it now (a smaller fluid needs less)");
  }
  return Refusal(RefusalCode::internal, doing + ": " + e.what());
}

// What a snapshot call is told when its work failed before it could be answered: out of memory
// (even for wording why), or else the server's own failure. Made at start: passing one on
// allocates nothing (std::runtime_error shares its message).
const Refusal kNoMemoryToAnswer(RefusalCode::resource_exhausted,
                                "the server ran out of memory answering this call");
const Refusal kFailedToAnswer(RefusalCode::internal, "the server failed answering this call");

const Refusal& unanswered(const std::exception& e) {
  return dynamic_cast<const std::bad_alloc*>(&e) ? kNoMemoryToAnswer : kFailedToAnswer;
}
const Refusal kStopping(RefusalCode::unavailable, "the server is shutting down");

// A steady clock's time as milliseconds, for ClientDebts.
double milliseconds_since_epoch(Clock::time_point time) {
  return std::chrono::duration<double, std::milli>(time.time_since_epoch()).count();
}

std::string no_session(const char* field, const ServerLimits& limits) {
  return std::string(field) + " opens no live session (it may have ended: sessions without " +
         "viewers end after " + std::to_string(limits.resume_grace.count()) + " s)";
}

// Runs one piece of the worker's work (`what`). Each piece answers its own caller; this is a last
// guard, so that what escapes one is logged instead of ending the worker and every session.
void run_guarded(const std::function<void()>& work, const char* what) {
  try {
    work();
  } catch (const std::exception& e) {
    spdlog::error("{} failed: {}", what, e.what());
  }
}

}  // namespace

SessionHub::SessionHub(gpu::Context& context, bool gpu_solver, ServerLimits limits,
                       std::optional<std::string> token, Metrics& metrics)
    : context_(&context),
      gpu_solver_(gpu_solver),
      limits_(limits),
      token_(std::move(token)),
      metrics_(&metrics),
      steps_(context),
      cpu_threads_(gpu_solver ? nullptr : std::make_shared<sim::ForkJoinPool>(0)),
      worker_([this] { run(); }) {}

SessionHub::~SessionHub() { stop(); }

void SessionHub::stop() {
  {
    std::lock_guard lock(mutex_);
    if (stopping_) return;
    stopping_ = true;
  }
  wake_.notify_all();
  worker_.join();
  encoders_.reset();
}

void SessionHub::post(std::function<void()> job) {
  {
    std::unique_lock lock(mutex_);
    if (!closed_) {
      jobs_.push_back(std::move(job));
      lock.unlock();
      wake_.notify_all();
      return;
    }
  }
  job();  // the worker has stopped: the job finds no session and says so
}

SessionHub::Opening SessionHub::find(const std::string& key, const char* field) const {
  Opening found;
  // Every session's keys compared: how long it takes tells nothing of which came close.
  for (const auto& [id, session] : sessions_) {
    const auto access = session->keys().opens(key);
    if (access && !session->failed()) found = {session, *access};
  }
  if (!found.session) throw Refusal(RefusalCode::not_found, no_session(field, limits_));
  return found;
}

std::optional<std::pair<std::shared_ptr<Session>, std::uint32_t>> SessionHub::find_resumed(
    const std::string& key) const {
  std::optional<std::pair<std::shared_ptr<Session>, std::uint32_t>> found;
  for (const auto& [id, session] : sessions_) {
    if (const auto viewer = session->viewer_resumed_by(key)) found.emplace(session, *viewer);
  }
  return found;
}

void SessionHub::open(v1::Hello hello, std::string address, std::shared_ptr<ViewerSink> sink,
                      std::function<void(Opened)> done) {
  post([this, hello = std::move(hello), address = std::move(address), sink = std::move(sink),
        done = std::move(done)] {
    Opened opened;
    std::shared_ptr<Session> session;
    std::uint32_t viewer = 0;
    const char* how = "created it";
    try {
      if (closed_) throw Refusal(RefusalCode::unavailable, "the server is shutting down");
      if (hello.has_join()) {
        const Opening joined = find(hello.join(), "Hello.join");
        session = joined.session;
        viewer = session->add_viewer(hello, sink, joined.access);
        how = "joined";
      } else if (hello.has_resume()) {
        if (const auto resumed = find_resumed(hello.resume().key())) {
          session = resumed->first;
          viewer = session->resume_viewer(hello, sink, resumed->second);
          how = "resumed";
        } else if (!hello.resume().session_key().empty()) {
          // The viewer was forgotten, its session may not be: a phone away past the grace
          // comes back to the fluid a device beside it still watches.
          const Opening rejoined = find(hello.resume().session_key(), "Hello.resume.session_key");
          session = rejoined.session;
          viewer = session->add_viewer(hello, sink, rejoined.access);
          how = "rejoined (its seat forgotten)";
        } else {
          throw Refusal(RefusalCode::not_found, no_session("Hello.resume.key", limits_));
        }
      } else {
        session = create_session(hello.create(), address);
        viewer = session->add_viewer(hello, sink, Access::control);
      }
      opened.access = session->access(viewer);
      spdlog::info("session {}: viewer {} {} from {} ({} particles, {} sessions)", session->id(),
                   viewer, how, address, session->state().particles(), sessions_.size());
    } catch (const Refusal& refusal) {
      opened.refusal = refusal;
    } catch (const std::exception& e) {  // this request fails alone
      opened.refusal = server_failure(e, "the server could not open the session");
    }
    if (opened.refusal) {
      done(std::move(opened));
      return;
    }
    opened.viewer = std::make_shared<ViewerLink>(*this, session, viewer);
    done(std::move(opened));
    sink->deliver(welcome(*session, viewer));
  });
}

std::shared_ptr<Session> SessionHub::create_session(const v1::NewSession& create,
                                                    const std::string& address) {
  if (sessions_.size() >= limits_.max_sessions) {
    throw Refusal(RefusalCode::resource_exhausted, "this server runs its limit of " +
                                                       std::to_string(limits_.max_sessions) +
                                                       " sessions; join one or try later");
  }
  const auto held = std::count_if(sessions_.begin(), sessions_.end(), [&](const auto& entry) {
    return entry.second->creator() == address;
  });
  if (held >= static_cast<std::ptrdiff_t>(limits_.max_sessions_per_address)) {
    throw Refusal(RefusalCode::resource_exhausted,
                  "this address already holds " + std::to_string(held) +
                      " sessions, this server's limit per address "
                      "(--max-sessions-per-address); end one (a session ends when its "
                      "viewers leave, or " +
                      std::to_string(limits_.resume_grace.count()) +
                      " s after they drop) or join one");
  }
  const std::string id = new_key();
  const SessionServices services{context_,     gpu_solver_, &steps_,  &frame_ms_per_megapixel_,
                                 cpu_threads_, &limits_,    metrics_, encoders_.get()};
  std::shared_ptr<Session> session;
  if (create.has_state()) {  // its scene, solver and count, not NewSession's
    session = std::make_shared<Session>(id, address, create.state(), services);
  } else {
    SessionSetup setup;
    if (!create.scene().empty()) setup.scene = sim::parse_scene(create.scene());
    if (!create.solver().empty()) setup.solver = sim::parse_solver(create.solver());
    setup.particles = create.particles();
    session = std::make_shared<Session>(id, address, setup, services);
  }
  // What the client owes, from sessions that ended and from its sessions that nobody watches
  // now (a client that drops or says goodbye and comes straight back starts no fresher).
  const auto now = Clock::now();
  std::set<std::string_view> clients{address};
  for (const auto& [other, running] : sessions_) {
    clients.insert(running->creator());
    if (running->creator() == address && running->viewer_count() == 0) {
      collect_debts(*running, now);
    }
  }
  // The share of each account's time that repays a debt: the client's part of the device's (the
  // simulation's least: what --busy-share adds depends on others' frames, and is not counted).
  const double sim_share = limits_.sim_share / double(clients.size());
  const double render_share =
      (gpu_solver_ ? 1.0 - limits_.sim_share : 1.0) / double(clients.size());
  const double now_ms = milliseconds_since_epoch(now);
  session->inherit_debts({sim_debts_.take(address, now_ms, sim_share),
                          render_debts_.take(address, now_ms, render_share)});
  sessions_.emplace(id, session);
  session_count_ = static_cast<std::uint32_t>(sessions_.size());
  metrics_->sessions = sessions_.size();
  return session;
}

std::shared_ptr<v1::ServerMessage> SessionHub::welcome(const Session& session,
                                                       std::uint32_t viewer) const {
  auto message = std::make_shared<v1::ServerMessage>();
  v1::Welcome& welcome = *message->mutable_welcome();
  welcome.set_session_id(session.id());
  welcome.set_viewer_id(viewer);
  *welcome.mutable_state() = session.state();
  const v1::ServerInfo server = info();
  *welcome.mutable_limits() = server.limits();
  *welcome.mutable_rules() = server.rules();
  *welcome.mutable_access() = session.access_message(viewer);
  return message;
}

void SessionHub::close(std::shared_ptr<Session> session, std::uint32_t viewer,
                       Departure departure) {
  post([session = std::move(session), viewer, departure] {
    session->remove_viewer(viewer, departure);
    spdlog::info("session {}: viewer {} {}", session->id(), viewer,
                 departure == Departure::left ? "left" : "dropped");
  });
}

void SessionHub::snapshot(
    std::string key, std::function<void(std::optional<v1::Snapshot>, std::optional<Refusal>)> done,
    std::function<bool()> given_up) {
  const char* field = "SnapshotRequest.key";
  beside_the_streams(
      key, field,
      [this, key, field, done] {
        std::optional<v1::Snapshot> snapshot;
        std::optional<Refusal> refusal;
        try {
          snapshot = find(key, field).session->snapshot();
        } catch (const Refusal& refused) {
          refusal = refused;
        } catch (const std::exception& e) {
          refusal = server_failure(e, "snapshot");
        }
        done(std::move(snapshot), std::move(refusal));
      },
      [done](const Refusal& refusal) { done(std::nullopt, refusal); }, std::move(given_up));
}

void SessionHub::load(std::string key, std::shared_ptr<const v1::Snapshot> state,
                      std::function<void(std::uint32_t, std::optional<Refusal>)> done,
                      std::function<bool()> given_up) {
  const char* field = "PutSnapshotRequest.key";
  beside_the_streams(
      key, field,
      [this, key, field, state, done] {
        std::uint32_t particles = 0;
        std::optional<Refusal> refusal;
        try {
          const Opening opening = find(key, field);
          if (opening.access != Access::control) {
            throw Refusal(RefusalCode::permission_denied,
                          "PutSnapshotRequest.key is the session's view key: replacing its fluid "
                          "needs the control key");
          }
          particles = opening.session->load(*state);
        } catch (const Refusal& refused) {
          refusal = refused;
        } catch (const std::exception& e) {
          refusal = server_failure(e, "snapshot");
        }
        done(particles, std::move(refusal));
      },
      [done](const Refusal& refusal) { done(0, refusal); }, std::move(given_up));
}

void SessionHub::beside_the_streams(const std::string& key, const char* field,
                                    std::function<void()> run,
                                    std::function<void(const Refusal&)> refuse,
                                    std::function<bool()> given_up) {
  // Each call is answered once, whatever fails: `run` ends in `done`, which throws nothing, so
  // what escapes came before it, and the call is refused instead (an answer that found no memory
  // to be worded in still goes, with its code: SnapshotCall::refuse).
  post([this, key, field, run = std::move(run), refuse = std::move(refuse),
        given_up = std::move(given_up)]() mutable {
    if (closed_) {
      refuse(kStopping);
      return;
    }
    try {
      const std::string session = find(key, field).session->id();
      side_work_.add(session,
                     {[run = std::move(run), refuse, given_up = std::move(given_up)] {
                        try {
                          if (given_up && given_up()) {
                            refuse(Refusal(RefusalCode::cancelled,
                                           "the call was cancelled while it waited its turn"));
                          } else {
                            run();
                          }
                        } catch (const std::exception& e) {
                          spdlog::error("a snapshot call's work failed: {}", e.what());
                          refuse(unanswered(e));
                        }
                      },
                      [refuse] { refuse(kStopping); }});
    } catch (const Refusal& refusal) {
      refuse(refusal);
    } catch (const std::exception& e) {
      refuse(unanswered(e));
    }
  });
}

v1::ServerInfo SessionHub::info() const {
  v1::ServerInfo info;
  info.set_version(kVersion);
  info.set_device(context_->info().name);
  v1::ServerLimits& limits = *info.mutable_limits();
  limits.set_max_sessions(limits_.max_sessions);
  limits.set_max_sessions_per_address(limits_.max_sessions_per_address);
  limits.set_max_particles(limits_.max_particles);
  limits.set_max_width(limits_.max_width);
  limits.set_max_height(limits_.max_height);
  limits.set_max_fps(limits_.max_fps);
  limits.set_max_viewers_per_session(limits_.max_viewers_per_session);
  limits.set_max_input_events_per_second(limits_.max_input_events_per_second);
  limits.set_resume_grace_seconds(static_cast<std::uint32_t>(limits_.resume_grace.count()));
  limits.set_idle_timeout_seconds(static_cast<std::uint32_t>(limits_.idle_timeout.count()));
  *info.mutable_rules() = input_rules(!render::FrameRenderer::mc_unsupported(*context_));
  info.set_token_required(token_.has_value());
  info.set_sessions(session_count_);
  return info;
}

void SessionHub::end_failed(Session& session, const std::exception& e) {
  spdlog::error("session {} failed: {}", session.id(), e.what());
  session.end_for_good(server_failure(e, "the session failed on the server"));
}

void SessionHub::end_all_on_gpu_failure(const std::string& why) {
  spdlog::error("{}; every session ends", why);
  const Refusal failed(RefusalCode::internal, "the server's GPU failed: " + why);
  for (auto& [id, session] : sessions_) session->end_all(failed);
  tick_serials_.clear();
}

void SessionHub::tick_all(Clock::time_point now) {
  bound_ticks_in_flight();
  std::vector<Session*> ticking;
  std::vector<GpuDemand> demands;
  for (auto& [id, session] : sessions_) {
    try {
      demands.push_back(session->prepare(now));
      ticking.push_back(session.get());
    } catch (const std::exception& e) {
      end_failed(*session, e);
    }
  }
  const double period_ms = 1000.0 / limits_.target_fps;
  const std::vector<GpuGrant> grants =
      grant_gpu_time(period_ms, limits_.sim_share, limits_.busy_share, demands);
  for (std::size_t k = 0; k < ticking.size(); ++k) {
    try {
      ticking[k]->simulate(grants[k]);
    } catch (const std::exception& e) {
      end_failed(*ticking[k], e);
      ticking[k] = nullptr;
    }
  }
  // Every session's steps in one submission, their passes side by side: small fluids are bound
  // by launches and barriers, which they now share.
  try {
    steps_.submit();
  } catch (const std::exception& e) {  // a lost device, or no memory to record with
    end_all_on_gpu_failure(e.what());
  }
  for (std::size_t k = 0; k < ticking.size(); ++k) {
    if (!ticking[k]) continue;
    try {
      ticking[k]->draw(grants[k], now);
    } catch (const std::exception& e) {
      end_failed(*ticking[k], e);
    }
  }
  tick_serials_.push_back(context_->last_submitted());
  end_idle_and_expired(now);
}

// At most two ticks' work on the GPU: the worker waits for the older before recording a third.
void SessionHub::bound_ticks_in_flight() {
  try {
    context_->release_finished();
    if (tick_serials_.size() == 2) {
      if (!context_->wait_for(tick_serials_.front(), kGpuStalled)) {
        end_all_on_gpu_failure("the GPU has not finished a tick's work in " +
                               std::to_string(kGpuStalled.count()) + " s");
      } else {
        tick_serials_.pop_front();
      }
    }
  } catch (const gpu::VulkanError& e) {  // the device is lost: every session with it
    end_all_on_gpu_failure(e.what());
  }
}

void SessionHub::collect_debts(Session& session, Clock::time_point now) {
  const Session::Debts debts = session.hand_over_debts();
  sim_debts_.record(session.creator(), debts.sim_ms, milliseconds_since_epoch(now));
  render_debts_.record(session.creator(), debts.render_ms, milliseconds_since_epoch(now));
}

void SessionHub::end_idle_and_expired(Clock::time_point now) {
  for (auto it = sessions_.begin(); it != sessions_.end();) {
    Session& session = *it->second;
    const auto idle = limits_.idle_timeout;
    if (idle.count() > 0 && session.viewer_count() > 0 && now - session.last_input() > idle) {
      spdlog::info("session {}: idle for {} s, its {} viewers' streams end", session.id(),
                   idle.count(), session.viewer_count());
      session.end_all(Refusal(RefusalCode::deadline_exceeded,
                              "no viewer touched, tilted or commanded the fluid for " +
                                  std::to_string(idle.count()) +
                                  " s (the server's --idle-timeout); resume to go on"));
    }
    if (session.expired(now)) {
      spdlog::info("session {} ended: its viewers left, or dropped more than {} s ago",
                   session.id(), limits_.resume_grace.count());
      metrics_->forget_session(session.id());
      collect_debts(session, now);
      it = sessions_.erase(it);
      trim_after_ = now + kTrimDelay;
    } else {
      metrics_->set_session(session.id(), session.figures());
      ++it;
    }
  }
  if (trim_after_ && now >= *trim_after_) {
    // glibc keeps what a large session freed for reuse, GBs of it after a million particles:
    // handed back to the system once its GPU objects have been retired too.
    trim_after_.reset();
    malloc_trim(0);
  }
  session_count_ = static_cast<std::uint32_t>(sessions_.size());
  metrics_->sessions = sessions_.size();
  metrics_->gpu_memory_bytes = context_->memory().block_bytes();
}

void SessionHub::collect_frames(Clock::time_point deadline) {
  try {
    context_->wait_for(context_->last_submitted(),
                       std::max(Clock::duration::zero(), deadline - Clock::now()));
  } catch (const gpu::VulkanError& e) {
    end_all_on_gpu_failure(e.what());
    return;
  }
  for (auto& [id, session] : sessions_) {
    try {
      session->send_frames(Session::FrameWait::finished_only);
    } catch (const std::exception& e) {
      end_failed(*session, e);
    }
  }
}

void SessionHub::run() {
  const auto interval = std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(1.0 / limits_.target_fps));
  auto next_tick = Clock::now();
  for (;;) {
    std::vector<std::function<void()>> jobs;
    {
      std::unique_lock lock(mutex_);
      wake_.wait_until(lock, next_tick, [this] { return stopping_ || !jobs_.empty(); });
      if (stopping_) break;
      jobs.swap(jobs_);
    }
    run_jobs(jobs);
    // Between ticks, within its share. Run after a tick's frames were collected instead, it left
    // the viewer of bench/snapshot_flood.sh 25.9-28.3 frames/s against 28.2-28.4.
    side_work_.run_due([] { return Clock::now(); });
    const auto now = Clock::now();
    if (now < next_tick) continue;
    tick_all(now);
    // Late ticks are not made up: the next one is an interval from now at the latest.
    next_tick = std::max(next_tick + interval, now);
    collect_frames(next_tick);
  }
  const Refusal stopping(RefusalCode::unavailable, "the server is shutting down");
  for (auto& [id, session] : sessions_) {
    session->end_all(stopping);
    metrics_->forget_session(id);
  }
  sessions_.clear();
  side_work_.refuse_all();
  // Jobs still queued get their answers: no session now.
  std::vector<std::function<void()>> jobs;
  {
    std::lock_guard lock(mutex_);
    closed_ = true;
    jobs.swap(jobs_);
  }
  run_jobs(jobs);
  metrics_->sessions = 0;
}

void SessionHub::run_jobs(std::vector<std::function<void()>>& jobs) {
  for (auto& job : jobs) run_guarded(job, "a worker job");
  jobs.clear();  // the jobs' captures (sessions among them) are released here, on the worker
}

}  // namespace fluidcast::server

// The server's sessions and the one GPU worker thread that runs them (docs/frame-loop.md):
// transports call in from their own threads and never touch Vulkan; the worker never blocks on the
// network.
#pragma once

#include <atomic>
#include <condition_variable>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "session.h"
#include "side_work.h"
#include "viewer_link.h"

namespace fluidcast::server {

class SessionHub {
 public:
  // token: what Hello.token must be, when the server wants one.
  SessionHub(gpu::Context& context, bool gpu_solver, ServerLimits limits,
             std::optional<std::string> token, Metrics& metrics);
  // Ends every stream with UNAVAILABLE and stops the worker.
  ~SessionHub();
  SessionHub(const SessionHub&) = delete;
  SessionHub& operator=(const SessionHub&) = delete;

  const ServerLimits& limits() const { return limits_; }
  const std::optional<std::string>& token() const { return token_; }
  Metrics& metrics() { return *metrics_; }

  struct Opened {
    std::shared_ptr<ViewerLink> viewer;  // null when refused
    Access access = Access::view;        // what the viewer's messages may do
    std::optional<Refusal> refusal;
  };
  // For a validated Hello from a client at `address` (an IP address, as text): creates, joins or
  // resumes a session on the worker, sends the Welcome to `sink`, then calls `done` (on the
  // worker's thread).
  void open(v1::Hello hello, std::string address, std::shared_ptr<ViewerSink> sink,
            std::function<void(Opened)> done);
  // Snapshots, for GetSnapshot (either of the session's keys) and PutSnapshot (its control key),
  // each in its session's line (SideWork); `done` runs on the worker's thread (the caller's once
  // the hub has stopped), once, whatever fails (it must throw nothing: it is how the call is
  // answered). A call whose `given_up` says so when its turn comes is not carried out (CANCELLED).
  void snapshot(std::string key,
                std::function<void(std::optional<v1::Snapshot>, std::optional<Refusal>)> done,
                std::function<bool()> given_up = {});
  // `snapshot` is read until `done` (a PutSnapshot's own request, not a copy of its megabytes).
  void load(std::string key, std::shared_ptr<const v1::Snapshot> snapshot,
            std::function<void(std::uint32_t particles, std::optional<Refusal>)> done,
            std::function<bool()> given_up = {});

  v1::ServerInfo info() const;
  // Ends every stream with UNAVAILABLE and stops the worker; idempotent.
  void stop();

 private:
  friend class ViewerLink;
  // The viewer's stream ended (ViewerLink::leave). A session outlives a viewer that dropped for the
  // grace period, and ends at the next tick once nobody watches and nobody may resume.
  void close(std::shared_ptr<Session> session, std::uint32_t viewer, Departure departure);
  void post(std::function<void()> job);
  // A snapshot call's work, `run` on the worker in the line of the session `key` opens (a
  // Refusal naming `field` when none), within SideWork's share; `refuse`d when it will not run
  // (the worker stops, or the call was `given_up` by its turn).
  void beside_the_streams(const std::string& key, const char* field, std::function<void()> run,
                          std::function<void(const Refusal&)> refuse,
                          std::function<bool()> given_up);
  void run();
  void run_jobs(std::vector<std::function<void()>>& jobs);
  void tick_all(Clock::time_point now);
  void bound_ticks_in_flight();
  // Ends the streams of sessions idle past --idle-timeout, removes expired ones (their memory goes
  // back to the system a little later), and updates the sessions' metrics.
  void end_idle_and_expired(Clock::time_point now);
  // Moves what `session` owes of GPU time to its client's ledger.
  void collect_debts(Session& session, Clock::time_point now);
  // A session that fails ends alone, with INTERNAL for its viewers; the others go on.
  void end_failed(Session& session, const std::exception& e);
  // The device is lost or stalled: every session's viewers get INTERNAL.
  void end_all_on_gpu_failure(const std::string& why);
  // How long a tick's work may take on the GPU before the device counts as stalled.
  static constexpr std::chrono::seconds kGpuStalled{10};
  // Between ticks: waits until the GPU has drawn this tick's frames or `deadline` comes, and
  // sends what is finished.
  void collect_frames(Clock::time_point deadline);
  // On the worker's thread: the session `key` (a view or control key) opens, and how far; a
  // Refusal (NOT_FOUND) naming `field` when none.
  struct Opening {
    std::shared_ptr<Session> session;
    Access access;
  };
  Opening find(const std::string& key, const char* field) const;
  // The session and viewer a resume key names, if any.
  std::optional<std::pair<std::shared_ptr<Session>, std::uint32_t>> find_resumed(
      const std::string& key) const;
  // A new session for a NewSession from `address`, within the server's limits (else a Refusal).
  std::shared_ptr<Session> create_session(const v1::NewSession& create, const std::string& address);
  std::shared_ptr<v1::ServerMessage> welcome(const Session& session, std::uint32_t viewer) const;

  gpu::Context* context_;
  bool gpu_solver_;
  ServerLimits limits_;
  std::optional<std::string> token_;
  Metrics* metrics_;
  // Reset when the hub stops, after the worker: frames still encoding reach their sinks while
  // the transports are still there.
  std::unique_ptr<codec::JpegEncoderPool> encoders_ = std::make_unique<codec::JpegEncoderPool>();

  // Worker state: only the worker touches it.
  // Every GPU solver's steps of a tick, submitted together (declared before the sessions, whose
  // solvers queue in it, so that it outlives them).
  sim::GpuStepBatch steps_;
  // What clients owe of GPU time from sessions that ended in debt.
  ClientDebts sim_debts_, render_debts_;
  CostEstimate frame_ms_per_megapixel_;  // SessionServices::frame_ms_per_megapixel
  // The threads every CPU solver steps on, one solver at a time (on the worker); none with GPU
  // solvers.
  std::shared_ptr<sim::ForkJoinPool> cpu_threads_;
  std::map<std::string, std::shared_ptr<Session>> sessions_;
  SideWork side_work_;  // the snapshot calls' work, waiting for its share of the worker
  // The newest submission of each of the last ticks: a tick starts once the one two before it has
  // finished on the GPU, so no more than one tick's work waits behind the one executing.
  std::deque<std::uint64_t> tick_serials_;
  // When to return freed memory to the system, after a session ended (its GPU objects retire
  // a few ticks later).
  static constexpr std::chrono::seconds kTrimDelay{2};
  std::optional<Clock::time_point> trim_after_;

  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::vector<std::function<void()>> jobs_;
  std::atomic<std::uint32_t> session_count_{0};
  bool stopping_ = false;
  bool closed_ = false;  // the worker has stopped: requests are refused at once
  std::thread worker_;
};

}  // namespace fluidcast::server

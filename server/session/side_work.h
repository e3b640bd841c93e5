// The worker's work for the calls beside the streams (GetSnapshot, PutSnapshot): outside any
// tick's grant, so held to a share of the worker's time of its own. Each session's calls wait in a
// line of their own, the lines take turns, and together they run at most kShare of the worker's
// wall time: clients that keep calling, over many connections at once, slow the calls, not the
// frames of every session (each call waits for the GPU, and a million particles take tens of ms
// to copy). Pure: the clock is given.
#pragma once

#include <chrono>
#include <deque>
#include <functional>
#include <map>
#include <string>

namespace fluidcast::server {

class SideWork {
 public:
  using Clock = std::chrono::steady_clock;
  // A call's work may take this share of the worker's time: after a job of d seconds, the next
  // starts d · (1 − kShare) / kShare later at the earliest.
  static constexpr double kShare = 0.25;

  struct Job {
    std::function<void()> run;
    std::function<void()> refuse;  // instead, when it will not run: the worker stops
  };
  // Into `session`'s line.
  void add(const std::string& session, Job job);
  // Runs the jobs that are due at `now()` (read before and after each), each session's line in
  // turn after the one served last.
  void run_due(const std::function<Clock::time_point()>& now);
  // Refuses every job still waiting.
  void refuse_all();

 private:
  std::map<std::string, std::deque<Job>> lines_;
  std::string served_last_;
  Clock::time_point next_start_{};
};

}  // namespace fluidcast::server

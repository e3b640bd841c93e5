// SIGINT (Ctrl-C) and SIGTERM as a request to stop a run cleanly, its figures said and the server
// told goodbye (a killed client's seat and session wait out the server's --resume-grace).
#pragma once

#include <signal.h>

#include <atomic>
#include <stop_token>
#include <thread>

namespace fluidcast::client {

class StopSignals {
 public:
  // Holds the two back from this thread and from every thread it starts later, so it is made
  // before any (none is interrupted, none ends the process), and waits for them on a thread of
  // its own. A signal ignored when the process started (a job in the background of a shell
  // without job control) stays ignored.
  StopSignals();
  ~StopSignals();
  StopSignals(const StopSignals&) = delete;
  StopSignals& operator=(const StopSignals&) = delete;

  // The first signal that asked to stop (0: none yet). The next one ends the process as it would
  // have, cutting short a stop that waits on a silent server.
  int received() const { return received_.load(); }
  // Requested with the first.
  std::stop_token stop_token() const { return stop_.get_token(); }

 private:
  sigset_t held_{};
  sigset_t before_{};
  std::atomic<int> received_{0};
  std::stop_source stop_;
  std::jthread waiter_;
};

}  // namespace fluidcast::client

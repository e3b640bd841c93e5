// SIGINT (Ctrl-C) and SIGTERM as a request to stop a run cleanly, its figures said and the server
// told goodbye (a killed client's seat and session wait out the server's --resume-grace), taken
// by the loop that can stop.
#pragma once

#include <signal.h>

namespace fluidcast::client {

class StopSignals {
 public:
  // Holds the two back from this thread and from every thread it starts later, so it is made
  // before any: no other thread is interrupted, none ends the process. A signal ignored when the
  // process started (a job in the background of a shell without job control) stays ignored.
  StopSignals();
  ~StopSignals();  // the mask as it was
  StopSignals(const StopSignals&) = delete;
  StopSignals& operator=(const StopSignals&) = delete;

  // The signal that asked to stop (0: none yet). Once one has, the next is no longer held back:
  // it ends the process as it would have, cutting short a stop that waits on a silent server.
  int take();

 private:
  sigset_t held_{};
  sigset_t before_{};
};

}  // namespace fluidcast::client

#include "stop_signals.h"

#include <pthread.h>

#include <ctime>
#include <initializer_list>

namespace fluidcast::client {

StopSignals::StopSignals() {
  sigemptyset(&held_);
  for (const int number : {SIGINT, SIGTERM}) {
    struct sigaction action {};
    if (sigaction(number, nullptr, &action) == 0 && action.sa_handler != SIG_IGN) {
      sigaddset(&held_, number);
    }
  }
  pthread_sigmask(SIG_BLOCK, &held_, &before_);
}

StopSignals::~StopSignals() { pthread_sigmask(SIG_SETMASK, &before_, nullptr); }

int StopSignals::take() {
  const timespec now{0, 0};
  const int number = sigtimedwait(&held_, nullptr, &now);
  if (number <= 0) return 0;
  pthread_sigmask(SIG_SETMASK, &before_, nullptr);
  return number;
}

}  // namespace fluidcast::client

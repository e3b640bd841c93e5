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
  waiter_ = std::jthread([this](std::stop_token leaving) {
    const timespec looks_every{0, 50'000'000};  // how soon it sees that it may go
    while (!leaving.stop_requested()) {
      const int number = sigtimedwait(&held_, nullptr, &looks_every);
      if (number <= 0) continue;
      if (received_.exchange(number) == 0) {
        stop_.request_stop();
        continue;
      }
      signal(number, SIG_DFL);
      sigset_t just_it;
      sigemptyset(&just_it);
      sigaddset(&just_it, number);
      pthread_sigmask(SIG_UNBLOCK, &just_it, nullptr);
      raise(number);
    }
  });
}

StopSignals::~StopSignals() {
  waiter_.request_stop();
  waiter_.join();
  // One that came since is taken here: the run ended without it, and the process ends anyway.
  const timespec no_wait{0, 0};
  while (sigtimedwait(&held_, nullptr, &no_wait) > 0) {
  }
  pthread_sigmask(SIG_SETMASK, &before_, nullptr);
}

}  // namespace fluidcast::client

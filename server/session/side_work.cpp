#include "side_work.h"

#include <utility>

namespace fluidcast::server {

void SideWork::add(const std::string& session, Job job) {
  const auto [line, made] = lines_.try_emplace(session);
  try {
    line->second.push_back(std::move(job));
  } catch (...) {  // no memory: no empty line left behind for run_due to take from
    if (made) lines_.erase(line);
    throw;
  }
}

void SideWork::run_due(const std::function<Clock::time_point()>& now) {
  for (Clock::time_point started = now(); !lines_.empty() && started >= next_start_;
       started = now()) {
    auto line = lines_.upper_bound(served_last_);
    if (line == lines_.end()) line = lines_.begin();
    served_last_ = line->first;
    Job job = std::move(line->second.front());
    line->second.pop_front();
    if (line->second.empty()) lines_.erase(line);
    job.run();
    const Clock::time_point ended = now();
    next_start_ = ended + std::chrono::duration_cast<Clock::duration>((ended - started) *
                                                                      ((1.0 - kShare) / kShare));
  }
}

void SideWork::refuse_all() {
  auto lines = std::exchange(lines_, {});
  for (auto& [session, jobs] : lines) {
    for (Job& job : jobs) job.refuse();
  }
}

}  // namespace fluidcast::server

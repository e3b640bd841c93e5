#include "snapshot_call.h"

#include <utility>

#include "session/refusal.h"
#include "status.h"

namespace fluidcast::server {

bool KeysInFlight::take(const std::string& key, std::function<void()> go_on) {
  {
    std::lock_guard lock(mutex_);
    if (!under_way_.insert(key).second) return false;
    const auto sending = being_sent_.find(key);
    if (sending != being_sent_.end() && sending->second >= kUnreadAnswers) {
      waiting_.emplace(key, std::move(go_on));
      return true;
    }
  }
  go_on();
  return true;
}

void KeysInFlight::answered(const std::string& key) {
  std::lock_guard lock(mutex_);
  under_way_.erase(key);
  ++being_sent_[key];
}

void KeysInFlight::sent(const std::string& key) {
  std::function<void()> go_on;
  {
    std::lock_guard lock(mutex_);
    const auto sending = being_sent_.find(key);
    if (sending == being_sent_.end()) return;
    if (--sending->second == 0) being_sent_.erase(sending);
    const auto waiting = waiting_.find(key);
    if (waiting == waiting_.end()) return;
    go_on = std::move(waiting->second);
    waiting_.erase(waiting);
  }
  go_on();
}

void SnapshotCall::hold(const std::string& key, const char* field, std::function<void()> go_on) {
  held_ = key;  // before take(): go_on may run on another thread at once
  if (!keys_->take(key, std::move(go_on))) {
    held_.reset();
    Finish(to_status(Refusal(RefusalCode::resource_exhausted,
                             std::string(field) +
                                 ": this key's last snapshot call is still under way; call again "
                                 "once it is answered")));
  }
}

void SnapshotCall::answer(const grpc::Status& status) {
  if (held_) {
    sending_ = std::exchange(held_, std::nullopt);
    keys_->answered(*sending_);
  }
  Finish(status);
}

void SnapshotCall::OnDone() {
  if (sending_) keys_->sent(*sending_);
  delete this;
}

}  // namespace fluidcast::server

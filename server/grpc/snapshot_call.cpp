#include "snapshot_call.h"

#include <utility>

#include "session/refusal.h"
#include "status.h"

namespace fluidcast::server {

bool KeysInFlight::take(const std::string& key) {
  std::lock_guard lock(mutex_);
  const auto sending = being_sent_.find(key);
  if (sending != being_sent_.end() && sending->second >= kUnreadAnswers) return false;
  return under_way_.insert(key).second;
}

void KeysInFlight::answered(const std::string& key) {
  std::lock_guard lock(mutex_);
  under_way_.erase(key);
  ++being_sent_[key];
}

void KeysInFlight::sent(const std::string& key) {
  std::lock_guard lock(mutex_);
  const auto sending = being_sent_.find(key);
  if (sending != being_sent_.end() && --sending->second == 0) being_sent_.erase(sending);
}

bool SnapshotCall::hold(const std::string& key, const char* field) {
  if (!keys_->take(key)) {
    Finish(to_status(Refusal(RefusalCode::resource_exhausted,
                             std::string(field) +
                                 ": this key's last snapshot call is still under way, or its "
                                 "answers are still unread; call again once they are read")));
    return false;
  }
  held_ = key;
  return true;
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

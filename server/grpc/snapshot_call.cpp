#include "snapshot_call.h"

#include <utility>

#include "session/refusal.h"
#include "status.h"

namespace fluidcast::server {

bool KeysInFlight::take(const std::string& key) {
  std::lock_guard lock(mutex_);
  return keys_.insert(key).second;
}

void KeysInFlight::release(const std::string& key) {
  std::lock_guard lock(mutex_);
  keys_.erase(key);
}

bool SnapshotCall::hold(const std::string& key, const char* field) {
  if (!keys_->take(key)) {
    Finish(to_status(Refusal(RefusalCode::resource_exhausted,
                             std::string(field) +
                                 ": this key's last snapshot call is still under way; call again "
                                 "once it has been answered")));
    return false;
  }
  held_ = key;
  return true;
}

void SnapshotCall::answer(const grpc::Status& status) {
  if (held_) keys_->release(*std::exchange(held_, std::nullopt));
  Finish(status);
}

}  // namespace fluidcast::server

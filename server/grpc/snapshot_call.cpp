#include "snapshot_call.h"

#include <utility>

#include "session/refusal.h"
#include "status.h"

namespace fluidcast::server {

bool SnapshotSlots::take(const SnapshotCaller& caller, std::function<void()> go_on) {
  {
    std::lock_guard lock(mutex_);
    if (!under_way_.insert(caller).second) return false;
    const auto sending = being_sent_.find(caller);
    if (sending != being_sent_.end() && sending->second >= kUnreadAnswers) {
      waiting_.emplace(caller, std::move(go_on));
      return true;
    }
  }
  go_on();
  return true;
}

void SnapshotSlots::answered(const SnapshotCaller& caller) {
  std::lock_guard lock(mutex_);
  under_way_.erase(caller);
  ++being_sent_[caller];
}

void SnapshotSlots::sent(const SnapshotCaller& caller) {
  std::function<void()> go_on;
  {
    std::lock_guard lock(mutex_);
    const auto sending = being_sent_.find(caller);
    if (sending == being_sent_.end()) return;
    if (--sending->second == 0) being_sent_.erase(sending);
    const auto waiting = waiting_.find(caller);
    if (waiting == waiting_.end()) return;
    go_on = std::move(waiting->second);
    waiting_.erase(waiting);
  }
  go_on();
}

void SnapshotCall::hold(const std::string& key, const char* field, std::function<void()> go_on) {
  held_ = SnapshotCaller{key, context_->peer()};  // before take(): go_on may run on another thread
  const bool taken = slots_->take(*held_, [this, go_on = std::move(go_on)] {
    if (context_->IsCancelled()) {
      answer(grpc::Status::CANCELLED);
      return;
    }
    try {
      go_on();
    } catch (const std::exception& e) {  // it runs in another call's OnDone: nothing may escape
      answer(to_status(Refusal(RefusalCode::internal, std::string("snapshot: ") + e.what())));
    }
  });
  if (!taken) {
    held_.reset();
    Finish(to_status(Refusal(RefusalCode::resource_exhausted,
                             std::string(field) +
                                 ": this connection's last snapshot call with this key is still "
                                 "under way; call again once it is answered")));
  }
}

void SnapshotCall::answer(const grpc::Status& status) {
  if (held_) {
    sending_ = std::exchange(held_, std::nullopt);
    slots_->answered(*sending_);
  }
  Finish(status);
}

void SnapshotCall::OnDone() {
  if (sending_) slots_->sent(*sending_);
  delete this;
}

}  // namespace fluidcast::server

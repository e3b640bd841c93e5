#include "snapshot_call.h"

#include <new>
#include <utility>

#include "peer_address.h"
#include "session/refusal.h"
#include "status.h"

namespace fluidcast::server {

SnapshotSlots::KeyAndAddress SnapshotSlots::key_and_address(const SnapshotCaller& caller) {
  return {caller.key, peer_address(caller.peer)};
}

SnapshotSlots::Take SnapshotSlots::take(const SnapshotCaller& caller, std::function<void()> go_on) {
  {
    std::lock_guard lock(mutex_);
    if (under_way_.contains(caller)) return Take::slot_held;
    Answers& answers = answers_[key_and_address(caller)];
    if (answers.held >= kUnreadAnswers) {
      if (answers.waiting.size() >= kMostWaiting) return Take::too_many_waiting;
      answers.waiting.push_back(std::move(go_on));
      under_way_.insert(caller);
      return Take::taken;
    }
    ++answers.held;
    under_way_.insert(caller);
  }
  go_on();
  return Take::taken;
}

void SnapshotSlots::answered(const SnapshotCaller& caller) {
  std::lock_guard lock(mutex_);
  under_way_.erase(caller);
}

void SnapshotSlots::sent(const SnapshotCaller& caller) {
  std::function<void()> go_on;
  {
    std::lock_guard lock(mutex_);
    const auto answers = answers_.find(key_and_address(caller));
    if (answers == answers_.end()) return;
    Answers& those = answers->second;
    if (!those.waiting.empty()) {  // its place goes to the call waiting longest
      go_on = std::move(those.waiting.front());
      those.waiting.pop_front();
    } else if (--those.held == 0) {
      answers_.erase(answers);
    }
  }
  if (go_on) go_on();
}

void SnapshotCall::hold(const std::string& key, const char* field, std::function<void()> go_on) {
  held_ = SnapshotCaller{key, context_->peer()};  // before take(): go_on may run on another thread
  const SnapshotSlots::Take taken = slots_->take(*held_, [this, go_on = std::move(go_on)] {
    if (context_->IsCancelled()) {
      answer(grpc::Status::CANCELLED);
      return;
    }
    // It runs in another call's OnDone, where nothing may escape. go_on hands the call to the
    // hub, which answers it: what escapes came before.
    try {
      go_on();
    } catch (const std::bad_alloc&) {
      answer(grpc::Status(grpc::StatusCode::RESOURCE_EXHAUSTED, ""));
    } catch (const std::exception&) {
      answer(grpc::Status(grpc::StatusCode::INTERNAL, ""));
    }
  });
  if (taken == SnapshotSlots::Take::taken) return;
  held_.reset();
  refuse(Refusal(
      RefusalCode::resource_exhausted,
      std::string(field) +
          (taken == SnapshotSlots::Take::slot_held
               ? ": this connection's last snapshot call with this key is still under way; call "
                 "again once it is answered"
               : ": " + std::to_string(SnapshotSlots::kMostWaiting) +
                     " snapshot calls with this key from this address wait already for its "
                     "unread answers to go out; read them first")));
}

void SnapshotCall::answer(grpc::Status status) noexcept {
  if (held_) {
    sending_ = std::exchange(held_, std::nullopt);
    slots_->answered(*sending_);
  }
  Finish(std::move(status));
}

void SnapshotCall::refuse(const Refusal& refusal) noexcept {
  grpc::Status status;
  try {
    status = to_status(refusal);
  } catch (const std::exception&) {  // no memory for its words: the code still says what it was
    status = grpc::Status(static_cast<grpc::StatusCode>(refusal.code()), "");
  }
  answer(std::move(status));
}

void SnapshotCall::OnDone() {
  if (sending_) slots_->sent(*sending_);
  delete this;
}

}  // namespace fluidcast::server

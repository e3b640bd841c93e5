// The snapshot calls (GetSnapshot, PutSnapshot): one at a time per key, from the moment a call is
// taken until it is answered. The shared worker then builds or loads at most one snapshot per key
// at a time, and a client that fires many calls at once gets RESOURCE_EXHAUSTED for all but one.
// An answer (a GetSnapshot's reply: up to ~24 MB) stays in the server's memory until the client
// has read it; a client that never read could otherwise have one answer after another queued, so
// a call that finds kUnreadAnswers of its key's answers still being sent waits, holding the key,
// until one of them has gone out (or its call was cancelled). It waits rather than being refused:
// a client that calls again as soon as it has read an answer may find the server not yet told
// that the answer went out.
#pragma once

#include <grpcpp/grpcpp.h>

#include <functional>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <string>

namespace fluidcast::server {

// The keys whose snapshot call is under way, and their answers still being sent.
class KeysInFlight {
 public:
  static constexpr int kUnreadAnswers = 2;

  // Takes `key` for a call and runs `go_on`: at once, or, while kUnreadAnswers of the key's
  // answers are being sent, on the thread that reports one of them sent. False (and `go_on` never
  // runs) when another call holds the key.
  bool take(const std::string& key, std::function<void()> go_on);
  // The call taken with `key` is answered: its reply is being sent. Another call may be taken.
  void answered(const std::string& key);
  // A reply of `key`'s (answered()) was sent, or its call cancelled.
  void sent(const std::string& key);

 private:
  std::mutex mutex_;
  std::set<std::string> under_way_;
  std::map<std::string, int> being_sent_;
  std::map<std::string, std::function<void()>> waiting_;
};

// One snapshot call's reactor; deletes itself when gRPC is done with the call.
class SnapshotCall final : public grpc::ServerUnaryReactor {
 public:
  explicit SnapshotCall(KeysInFlight& keys) : keys_(&keys) {}

  // Holds `key`'s slot for this call and runs `go_on` (see KeysInFlight::take), which ends in
  // answer(); when another call holds the slot, finishes this one with RESOURCE_EXHAUSTED naming
  // `field`.
  void hold(const std::string& key, const char* field, std::function<void()> go_on);
  // Answers the call, first letting its key go: a client that calls again as soon as it has its
  // answer finds the key free.
  void answer(const grpc::Status& status);

  // The reply was sent, or the call cancelled.
  void OnDone() override;

 private:
  KeysInFlight* keys_;
  std::optional<std::string> held_;
  std::optional<std::string> sending_;
};

}  // namespace fluidcast::server

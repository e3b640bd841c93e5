// The snapshot calls (GetSnapshot, PutSnapshot): one at a time per key and connection, from the
// moment a call is taken until it is answered. The shared worker then builds or loads at most one
// snapshot at a time for each, and a client that fires many calls at once gets RESOURCE_EXHAUSTED
// for all but one; viewers sharing a session's view key do not hold each other up.
// An answer (a GetSnapshot's reply: up to ~24 MB) stays in the server's memory until the client
// has read it; a client that never read could otherwise have one answer after another queued, so
// a call that finds kUnreadAnswers of its connection's answers with its key still being sent waits
// until one of them has gone out (or its call ended). It waits rather than being refused: a
// client that calls again as soon as it has read an answer may find the server not yet told that
// the answer went out.
#pragma once

#include <grpcpp/grpcpp.h>

#include <compare>
#include <functional>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <string>

namespace fluidcast::server {

// Whose snapshot call it is: the session key it gives and the connection it came on (gRPC's peer,
// address and port).
struct SnapshotCaller {
  std::string key;
  std::string peer;
  auto operator<=>(const SnapshotCaller&) const = default;
};

// Each caller's slot: its snapshot call under way (or waiting), and its answers still being sent.
class SnapshotSlots {
 public:
  static constexpr int kUnreadAnswers = 2;

  // Takes `caller`'s slot for a call and runs `go_on`: at once, or, while kUnreadAnswers of the
  // caller's answers are being sent, on the thread that reports one of them sent. False (and
  // `go_on` never runs) when another call holds the slot.
  bool take(const SnapshotCaller& caller, std::function<void()> go_on);
  // The call taken for `caller` is answered: its reply is being sent. Another call may be taken.
  void answered(const SnapshotCaller& caller);
  // A reply of `caller`'s (answered()) was sent, or its call ended before it was.
  void sent(const SnapshotCaller& caller);

 private:
  std::mutex mutex_;
  std::set<SnapshotCaller> under_way_;
  std::map<SnapshotCaller, int> being_sent_;
  std::map<SnapshotCaller, std::function<void()>> waiting_;
};

// One snapshot call's reactor; deletes itself when gRPC is done with the call.
class SnapshotCall final : public grpc::ServerUnaryReactor {
 public:
  SnapshotCall(SnapshotSlots& slots, const grpc::CallbackServerContext& context)
      : slots_(&slots), context_(&context) {}

  // Holds the slot of this call's key and connection and runs `go_on` (see SnapshotSlots::take),
  // which ends in answer(), unless the client has cancelled the call by then (a PutSnapshot it
  // gave up on is not carried out later). When another call holds the slot, finishes this one
  // with RESOURCE_EXHAUSTED naming `field`.
  void hold(const std::string& key, const char* field, std::function<void()> go_on);
  // Answers the call, first letting its slot go: a client that calls again as soon as it has its
  // answer finds the slot free.
  void answer(const grpc::Status& status);

  // The reply was sent, or the call ended before it was.
  void OnDone() override;

 private:
  SnapshotSlots* slots_;
  const grpc::CallbackServerContext* context_;
  std::optional<SnapshotCaller> held_;
  std::optional<SnapshotCaller> sending_;
};

}  // namespace fluidcast::server

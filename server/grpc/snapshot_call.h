// The snapshot calls (GetSnapshot, PutSnapshot): one at a time per key and connection, from the
// moment a call is taken until it is answered. The shared worker then builds or loads at most one
// snapshot at a time for each, and a client that fires many calls at once on one connection gets
// RESOURCE_EXHAUSTED for all but one; viewers sharing a session's view key are not refused for
// each other.
// An answer (a GetSnapshot's reply: up to ~24 MB) stays in the server's memory until the client
// has read it; a client that never read could otherwise have one answer after another queued, so
// a call that finds kUnreadAnswers calls with its key from its address gone on and not yet sent
// waits until one of them has gone out (or its call ended). By address, not connection: one
// client's connections (up to --max-connections-per-address) would each hold as many. It waits
// rather than being refused: a client that calls again as soon as it has read an answer may find
// the server not yet told that the answer went out. Only a few wait (kMostWaiting): each holds
// its request, and a PutSnapshot's is the whole fluid.
#pragma once

#include <grpcpp/grpcpp.h>

#include <compare>
#include <cstddef>
#include <deque>
#include <functional>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <utility>

#include "session/refusal.h"

namespace fluidcast::server {

// Whose snapshot call it is: the session key it gives and the connection it came on (gRPC's peer,
// address and port).
struct SnapshotCaller {
  std::string key;
  std::string peer;
  auto operator<=>(const SnapshotCaller&) const = default;
};

// Each caller's slot: its snapshot call under way (or waiting); and the calls with each key from
// each address not yet sent.
class SnapshotSlots {
 public:
  static constexpr int kUnreadAnswers = 2;
  // Calls with a key from an address waiting for one of its answers to go out: each holds its
  // request (a PutSnapshot's is the whole fluid, ~24 MB at 1M particles) until its turn.
  static constexpr std::size_t kMostWaiting = 4;

  enum class Take {
    taken,             // `go_on` runs: now, or once an answer of the address's has gone out
    slot_held,         // another call holds the slot
    too_many_waiting,  // kMostWaiting calls with the key from the address wait already
  };
  // Takes `caller`'s slot for a call and runs `go_on`: at once, or, while kUnreadAnswers calls
  // with its key from its address are worked on or being sent, on the thread that reports one of
  // them sent (the calls waiting for an address in the order they came). Otherwise `go_on` never
  // runs, and the slot stays as it was.
  Take take(const SnapshotCaller& caller, std::function<void()> go_on);
  // The call taken for `caller` is answered: its reply is being sent. Another call may be taken.
  void answered(const SnapshotCaller& caller);
  // A reply of `caller`'s (answered()) was sent, or its call ended before it was.
  void sent(const SnapshotCaller& caller);

 private:
  // A key and the address of the connections it comes on.
  using KeyAndAddress = std::pair<std::string, std::string>;
  static KeyAndAddress key_and_address(const SnapshotCaller& caller);
  struct Answers {
    // Calls gone on and not yet sent (worked on, or answered and being sent): at most
    // kUnreadAnswers.
    int held = 0;
    std::deque<std::function<void()>> waiting;  // calls waiting for one of them to go out
  };

  std::mutex mutex_;
  std::set<SnapshotCaller> under_way_;
  std::map<KeyAndAddress, Answers> answers_;
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
  // answer finds the slot free. Throws nothing: every call ends here, once.
  void answer(grpc::Status status) noexcept;
  // Answers with the refusal as a status; with its code alone where wording it found no memory.
  void refuse(const Refusal& refusal) noexcept;

  // The reply was sent, or the call ended before it was.
  void OnDone() override;

 private:
  SnapshotSlots* slots_;
  const grpc::CallbackServerContext* context_;
  std::optional<SnapshotCaller> held_;
  std::optional<SnapshotCaller> sending_;
};

}  // namespace fluidcast::server

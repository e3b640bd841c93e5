// The snapshot calls (GetSnapshot, PutSnapshot): one at a time per key, from the moment a call is
// taken until it is answered. The shared worker then builds or loads at most one snapshot per key
// at a time, and a client that fires many calls at once gets RESOURCE_EXHAUSTED for all but one.
#pragma once

#include <grpcpp/grpcpp.h>

#include <mutex>
#include <optional>
#include <set>
#include <string>

namespace fluidcast::server {

// The keys whose snapshot call is under way.
class KeysInFlight {
 public:
  // False when `key`'s call is under way.
  bool take(const std::string& key);
  void release(const std::string& key);

 private:
  std::mutex mutex_;
  std::set<std::string> keys_;
};

// One snapshot call's reactor; deletes itself when gRPC is done with the call.
class SnapshotCall final : public grpc::ServerUnaryReactor {
 public:
  explicit SnapshotCall(KeysInFlight& keys) : keys_(&keys) {}

  // Holds `key`'s slot for this call. False, and the call finished with RESOURCE_EXHAUSTED naming
  // `field`, when another call holds it.
  bool hold(const std::string& key, const char* field);
  // Answers the call, first letting its key go: a client that calls again as soon as it has its
  // answer finds the key free.
  void answer(const grpc::Status& status);

  void OnDone() override { delete this; }

 private:
  KeysInFlight* keys_;
  std::optional<std::string> held_;
};

}  // namespace fluidcast::server

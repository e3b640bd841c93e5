#include "fluidcast_service.h"

#include "grpc/peer_address.h"
#include "session/validation.h"
#include "status.h"
#include "stream_reactor.h"

namespace fluidcast::server {
namespace {

// The token and the key a snapshot call gives, in the fields named; a refusal finishes the call
// (true).
template <class Request>
bool refused(grpc::ServerUnaryReactor* reactor, const Request& request,
             const std::optional<std::string>& token, const char* token_field,
             const char* key_field) {
  try {
    validate_token(request.token(), token, token_field);
    validate_key(request.key(), key_field);
    return false;
  } catch (const Refusal& refusal) {
    reactor->Finish(to_status(refusal));
    return true;
  }
}

}  // namespace

grpc::ServerBidiReactor<grpc::ByteBuffer, grpc::ByteBuffer>* FluidcastService::Stream(
    grpc::CallbackServerContext* context) {
  return new StreamReactor(*hub_, peer_address(context->peer()));  // deletes itself in OnDone
}

grpc::ServerUnaryReactor* FluidcastService::GetServerInfo(grpc::CallbackServerContext* context,
                                                          const v1::GetServerInfoRequest*,
                                                          v1::ServerInfo* reply) {
  *reply = hub_->info();
  auto* reactor = context->DefaultReactor();
  reactor->Finish(grpc::Status::OK);
  return reactor;
}

grpc::ServerUnaryReactor* FluidcastService::GetSnapshot(grpc::CallbackServerContext* context,
                                                        const v1::SnapshotRequest* request,
                                                        v1::Snapshot* reply) {
  auto* call = new SnapshotCall(snapshot_slots_, *context);  // deletes itself in OnDone
  if (refused(call, *request, hub_->token(), "SnapshotRequest.token", "SnapshotRequest.key")) {
    return call;
  }
  call->hold(request->key(), "SnapshotRequest.key", [this, call, context, request, reply] {
    hub_->snapshot(
        request->key(),
        [call, reply](std::optional<v1::Snapshot> snapshot, std::optional<Refusal> refusal) {
          if (refusal) return call->refuse(*refusal);
          *reply = std::move(*snapshot);  // a swap: nothing thrown after the work is done
          call->answer(grpc::Status::OK);
        },
        [context] { return context->IsCancelled(); });
  });
  return call;
}

grpc::ServerUnaryReactor* FluidcastService::PutSnapshot(grpc::CallbackServerContext* context,
                                                        const v1::PutSnapshotRequest* request,
                                                        v1::PutSnapshotReply* reply) {
  auto* call = new SnapshotCall(snapshot_slots_, *context);  // deletes itself in OnDone
  if (refused(call, *request, hub_->token(), "PutSnapshotRequest.token",
              "PutSnapshotRequest.key")) {
    return call;
  }
  if (!request->has_snapshot()) {
    call->Finish(to_status(
        Refusal(RefusalCode::invalid_argument, "PutSnapshotRequest.snapshot is missing")));
    return call;
  }
  call->hold(request->key(), "PutSnapshotRequest.key", [this, call, context, request, reply] {
    // The request's own snapshot, not a copy: gRPC frees the request once the call is answered,
    // after the hub's last read of it.
    hub_->load(
        request->key(),
        std::shared_ptr<const v1::Snapshot>(std::shared_ptr<void>(), &request->snapshot()),
        [call, reply](std::uint32_t particles, std::optional<Refusal> refusal) {
          if (refusal) return call->refuse(*refusal);
          reply->set_particles(particles);
          call->answer(grpc::Status::OK);
        },
        [context] { return context->IsCancelled(); });
  });
  return call;
}

}  // namespace fluidcast::server

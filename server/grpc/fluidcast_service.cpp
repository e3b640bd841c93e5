#include "fluidcast_service.h"

#include "grpc/peer_address.h"
#include "session/validation.h"
#include "status.h"
#include "stream_reactor.h"

namespace fluidcast::server {
namespace {

// The token and the key a snapshot call gives; a refusal finishes the call (true).
bool refused(grpc::ServerUnaryReactor* reactor, const std::string& given,
             const std::optional<std::string>& token, const std::string& key, const char* field) {
  try {
    validate_token(given, token);
    validate_key(key, field);
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
  auto* reactor = context->DefaultReactor();
  if (refused(reactor, request->token(), hub_->token(), request->key(), "SnapshotRequest.key")) {
    return reactor;
  }
  hub_->snapshot(request->key(), [reactor, reply](std::optional<v1::Snapshot> snapshot,
                                                  std::optional<Refusal> refusal) {
    if (refusal) {
      reactor->Finish(to_status(*refusal));
      return;
    }
    *reply = std::move(*snapshot);
    reactor->Finish(grpc::Status::OK);
  });
  return reactor;
}

grpc::ServerUnaryReactor* FluidcastService::PutSnapshot(grpc::CallbackServerContext* context,
                                                        const v1::PutSnapshotRequest* request,
                                                        v1::PutSnapshotReply* reply) {
  auto* reactor = context->DefaultReactor();
  if (refused(reactor, request->token(), hub_->token(), request->key(), "PutSnapshotRequest.key")) {
    return reactor;
  }
  hub_->load(request->key(), request->snapshot(),
             [reactor, reply](std::uint32_t particles, std::optional<Refusal> refusal) {
               if (refusal) {
                 reactor->Finish(to_status(*refusal));
                 return;
               }
               reply->set_particles(particles);
               reactor->Finish(grpc::Status::OK);
             });
  return reactor;
}

}  // namespace fluidcast::server

// The Fluidcast gRPC service (callback API): the Stream call and the unary requests, all handed to
// the SessionHub.
#pragma once

#include "fluidcast/v1/fluidcast.grpc.pb.h"
#include "grpc/snapshot_call.h"
#include "session/session_hub.h"

namespace fluidcast::server {

// The Stream call is raw (bytes both ways): StreamReactor parses what it reads.
class FluidcastService final
    : public v1::Fluidcast::WithRawCallbackMethod_Stream<
          v1::Fluidcast::WithCallbackMethod_GetServerInfo<
              v1::Fluidcast::WithCallbackMethod_GetSnapshot<
                  v1::Fluidcast::WithCallbackMethod_PutSnapshot<v1::Fluidcast::Service>>>> {
 public:
  explicit FluidcastService(SessionHub& hub) : hub_(&hub) {}

  grpc::ServerBidiReactor<grpc::ByteBuffer, grpc::ByteBuffer>* Stream(
      grpc::CallbackServerContext* context) override;
  grpc::ServerUnaryReactor* GetServerInfo(grpc::CallbackServerContext* context,
                                          const v1::GetServerInfoRequest* request,
                                          v1::ServerInfo* reply) override;
  grpc::ServerUnaryReactor* GetSnapshot(grpc::CallbackServerContext* context,
                                        const v1::SnapshotRequest* request,
                                        v1::Snapshot* reply) override;
  grpc::ServerUnaryReactor* PutSnapshot(grpc::CallbackServerContext* context,
                                        const v1::PutSnapshotRequest* request,
                                        v1::PutSnapshotReply* reply) override;

 private:
  SessionHub* hub_;
  SnapshotSlots snapshot_slots_;
};

}  // namespace fluidcast::server

// The Fluidcast gRPC service (callback API): the Stream call and the unary requests, all handed to
// the SessionHub.
#pragma once

#include <functional>
#include <string>
#include <string_view>

#include "fluidcast/v1/fluidcast.grpc.pb.h"
#include "session/session_hub.h"

namespace fluidcast::server {

// The Stream call is raw (bytes both ways): StreamReactor parses what it reads.
class FluidcastService final
    : public v1::Fluidcast::WithRawCallbackMethod_Stream<
          v1::Fluidcast::WithCallbackMethod_GetServerInfo<
              v1::Fluidcast::WithCallbackMethod_GetSnapshot<
                  v1::Fluidcast::WithCallbackMethod_PutSnapshot<v1::Fluidcast::Service>>>> {
 public:
  // What per-address limits count for a call's gRPC peer string (peer_address, or the
  // GrpcListener's address_of for connections it handed to gRPC).
  using AddressOf = std::function<std::string(std::string_view grpc_peer)>;

  FluidcastService(SessionHub& hub, AddressOf address_of)
      : hub_(&hub), address_of_(std::move(address_of)) {}

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
  AddressOf address_of_;
};

}  // namespace fluidcast::server

// One gRPC Stream call: validates what the client sends, hands it to its session, and writes the
// session's frames — the newest wins, one write in flight (gRPC's callback rules: never Finish
// with a write outstanding, never block in a reaction). A stream that sends no Hello within
// ServerLimits::hello_timeout is ended with DEADLINE_EXCEEDED. Messages arrive as bytes for the
// StreamProtocol to parse, so that one that is not a ClientMessage ends the stream with
// INVALID_ARGUMENT (gRPC's own parsing would report it like the client closing its side).
#pragma once

#include <grpcpp/alarm.h>
#include <grpcpp/grpcpp.h>
#include <grpcpp/support/byte_buffer.h>

#include <atomic>
#include <memory>

#include "fluidcast/v1/fluidcast.grpc.pb.h"
#include "session/session_hub.h"
#include "session/stream_protocol.h"

namespace fluidcast::server {

class GrpcViewerSink;

class StreamReactor final : public grpc::ServerBidiReactor<grpc::ByteBuffer, grpc::ByteBuffer> {
 public:
  // `address`: the client's, for per-address limits.
  StreamReactor(SessionHub& hub, std::string address);

  void OnReadDone(bool ok) override;
  void OnWriteDone(bool ok) override;
  void OnCancel() override;
  void OnDone() override;

 private:
  friend class GrpcViewerSink;
  // Under the sink's lock, while the stream lives.
  void on_opened(SessionHub::Opened opened);
  void refuse(const Refusal& refusal);

  SessionHub* hub_;
  std::shared_ptr<GrpcViewerSink> sink_;
  grpc::ByteBuffer incoming_;
  StreamProtocol protocol_;
  grpc::Alarm hello_deadline_;
  // Set once, on the worker's thread, before the next read starts; read by reactions after.
  std::shared_ptr<ViewerLink> viewer_;
  std::string address_;
  // OnCancel came: the stream broke or the client cancelled (a viewer that may resume), rather
  // than the client closing its side and reading the status (one that left).
  std::atomic<bool> cancelled_{false};
};

}  // namespace fluidcast::server

// The plaintext gRPC port, accepted here rather than by gRPC: gRPC 1.51 stops accepting for good
// after one failed accept (descriptors exhausted: "Failed accept4: Too many open files"), while
// this Listener waits and goes on. Each connection is handed to the gRPC server as it comes.
// (gRPC over TLS cannot be handed over this way; with --tls-cert, gRPC listens itself.)
#pragma once

#include <grpcpp/server.h>

#include <boost/asio/io_context.hpp>
#include <string>
#include <thread>

#include "net/listener.h"

namespace fluidcast::server {

class GrpcListener {
 public:
  // Listens at once (throws std::runtime_error when it cannot); hands nothing over until start().
  GrpcListener(const std::string& address, unsigned short port);
  ~GrpcListener();
  GrpcListener(const GrpcListener&) = delete;
  GrpcListener& operator=(const GrpcListener&) = delete;

  // `server` (built without listening ports) must outlive this listener's stop().
  void start(grpc::Server& server);
  void stop();

  unsigned short port() const { return listener_.port(); }
  bool accepting() const { return listener_.accepting(); }

 private:
  boost::asio::io_context io_;
  Listener listener_;
  std::thread thread_;
};

}  // namespace fluidcast::server

// The plaintext gRPC port, accepted here and each connection handed to gRPC, rather than accepted
// by gRPC: gRPC 1.51 stops accepting for good after one failed accept ("Failed accept4: Too many
// open files"), while a Listener waits and goes on once descriptors are back. (gRPC over TLS
// cannot be handed over this way: with --tls-cert, gRPC listens itself.)
#pragma once

#include <grpcpp/server.h>

#include <boost/asio/io_context.hpp>
#include <mutex>
#include <string>
#include <string_view>
#include <thread>
#include <unordered_map>

#include "net/listener.h"

namespace fluidcast::server {

class GrpcListener {
 public:
  // Listens at once (throws std::runtime_error when it cannot); hands nothing over until start().
  GrpcListener(const std::string& address, unsigned short port);
  ~GrpcListener();
  GrpcListener(const GrpcListener&) = delete;
  GrpcListener& operator=(const GrpcListener&) = delete;

  // `server` (built without listening ports) must outlive stop().
  void start(grpc::Server& server);
  void stop();

  unsigned short port() const { return listener_.port(); }
  bool accepting() const { return listener_.accepting(); }

  // The client's address behind a gRPC peer string: gRPC names a connection handed to it
  // "fd:N", which says nothing of where it came from; any other peer string as peer_address.
  std::string address_of(std::string_view grpc_peer) const;

 private:
  boost::asio::io_context io_;
  Listener listener_;
  std::thread thread_;
  mutable std::mutex mutex_;
  // By descriptor: a number is reused only once gRPC has closed the connection that had it.
  std::unordered_map<int, std::string> addresses_;
};

}  // namespace fluidcast::server

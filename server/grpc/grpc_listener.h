// The gRPC port, accepted here and each connection handed to gRPC (which makes it plaintext or
// TLS), rather than accepted by gRPC: gRPC 1.51 stops accepting for good after one failed accept
// ("Failed accept4: Too many open files"), while a Listener waits and goes on once descriptors
// are back; and a connection over --max-connections-per-address is closed before gRPC sees it.
#pragma once

#include <grpcpp/server_builder.h>
#include <sys/types.h>

#include <boost/asio/io_context.hpp>
#include <memory>
#include <string>
#include <thread>
#include <unordered_map>

#include "net/connection_limits.h"
#include "net/listener.h"

namespace fluidcast::server {

class GrpcListener {
 public:
  // Listens at once (throws std::runtime_error when it cannot); hands nothing over until start().
  GrpcListener(const std::string& address, unsigned short port, ConnectionLimits limits);
  ~GrpcListener();
  GrpcListener(const GrpcListener&) = delete;
  GrpcListener& operator=(const GrpcListener&) = delete;

  // Hands connections to `acceptor` (of a server built without listening ports, and started),
  // which must outlive stop().
  void start(grpc::experimental::ExternalConnectionAcceptor& acceptor);
  void stop();

  unsigned short port() const { return listener_.port(); }
  bool accepting() const { return listener_.accepting(); }

 private:
  // A connection handed to gRPC, by its descriptor. gRPC does not say when it closes one: a
  // descriptor that no longer names the same socket (device and inode) was closed. Touched only
  // on the listener's one thread.
  struct Handed {
    dev_t device;
    ino_t inode;
    std::shared_ptr<ConnectionLimits::Slot> slot;
  };
  // A slot for a connection from `client`, after forgetting its closed ones if it had none.
  std::shared_ptr<ConnectionLimits::Slot> admit(const boost::asio::ip::address& client);
  // Only `client`'s are looked at (fstat): a client at its limit that keeps connecting costs the
  // accept loop little more than its own connections.
  void forget_closed(const boost::asio::ip::address& client);

  boost::asio::io_context io_;
  Listener listener_;
  ConnectionLimits limits_;
  std::thread thread_;
  std::unordered_map<int, Handed> handed_;
};

}  // namespace fluidcast::server

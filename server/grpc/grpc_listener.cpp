#include "grpc/grpc_listener.h"

#include <fcntl.h>
#include <grpcpp/server_posix.h>

#include <charconv>

#include "grpc/peer_address.h"

namespace fluidcast::server {

GrpcListener::GrpcListener(const std::string& address, unsigned short port)
    : listener_(io_, address, port, "gRPC") {}

GrpcListener::~GrpcListener() { stop(); }

void GrpcListener::start(grpc::Server& server) {
  listener_.start(
      [this, &server](boost::asio::ip::tcp::socket socket, boost::asio::ip::address client) {
        boost::system::error_code error;
        // gRPC reads and writes without waiting: a blocking socket would hold one of its polling
        // threads in read() until the client spoke, and every other connection's pings with it.
        socket.non_blocking(true, error);
        if (error) return;
        socket.set_option(boost::asio::ip::tcp::no_delay(true), error);
        if (error) return;
        const int fd = socket.release();
        fcntl(fd, F_SETFD, FD_CLOEXEC);
        {
          const std::lock_guard lock(mutex_);
          addresses_[fd] = client.to_string();
        }
        grpc::AddInsecureChannelFromFd(&server, fd);
      });
  thread_ = std::thread([this] { io_.run(); });
}

void GrpcListener::stop() {
  io_.stop();
  if (thread_.joinable()) thread_.join();
  listener_.close();
}

std::string GrpcListener::address_of(std::string_view grpc_peer) const {
  constexpr std::string_view kHandedOver = "fd:";
  if (grpc_peer.substr(0, kHandedOver.size()) != kHandedOver) return peer_address(grpc_peer);
  const std::string_view number = grpc_peer.substr(kHandedOver.size());
  int fd = -1;
  std::from_chars(number.data(), number.data() + number.size(), fd);
  const std::lock_guard lock(mutex_);
  const auto found = addresses_.find(fd);
  return found == addresses_.end() ? std::string(grpc_peer) : found->second;
}

}  // namespace fluidcast::server

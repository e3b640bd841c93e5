#include "grpc/grpc_listener.h"

#include <fcntl.h>
#include <grpcpp/server_posix.h>
#include <sys/stat.h>

#include <charconv>

#include "grpc/peer_address.h"

namespace fluidcast::server {

GrpcListener::GrpcListener(const std::string& address, unsigned short port, ConnectionLimits limits)
    : listener_(io_, address, port, "gRPC"), limits_(std::move(limits)) {}

GrpcListener::~GrpcListener() { stop(); }

void GrpcListener::start(grpc::Server& server) {
  listener_.start(
      [this, &server](boost::asio::ip::tcp::socket socket, boost::asio::ip::address client) {
        std::shared_ptr<ConnectionLimits::Slot> slot = admit(client);
        if (!slot) return;  // over the limit: the socket closes here
        boost::system::error_code error;
        // gRPC reads and writes without waiting: a blocking socket would hold one of its polling
        // threads in read() until the client spoke, and every other connection's pings with it.
        socket.non_blocking(true, error);
        if (error) return;
        socket.set_option(boost::asio::ip::tcp::no_delay(true), error);
        if (error) return;
        struct stat status {};
        if (fstat(socket.native_handle(), &status) != 0) return;
        const int fd = socket.release();
        fcntl(fd, F_SETFD, FD_CLOEXEC);
        {
          const std::lock_guard lock(mutex_);
          // A number in the table is taken again only once gRPC closed the connection that had it.
          handed_[fd] = {status.st_dev, status.st_ino, client.to_string(), std::move(slot)};
        }
        grpc::AddInsecureChannelFromFd(&server, fd);
      });
  thread_ = std::thread([this] { io_.run(); });
}

std::shared_ptr<ConnectionLimits::Slot> GrpcListener::admit(
    const boost::asio::ip::address& client) {
  if (auto slot = limits_.admit(client)) return slot;
  const std::lock_guard lock(mutex_);
  forget_closed();
  return limits_.admit(client);
}

void GrpcListener::forget_closed() {
  std::erase_if(handed_, [](const auto& entry) {
    const auto& [fd, handed] = entry;
    struct stat status {};
    return fstat(fd, &status) != 0 || status.st_dev != handed.device ||
           status.st_ino != handed.inode;
  });
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
  const auto found = handed_.find(fd);
  return found == handed_.end() ? std::string(grpc_peer) : found->second.address;
}

}  // namespace fluidcast::server

#include "grpc/grpc_listener.h"

#include <fcntl.h>
#include <sys/stat.h>

namespace fluidcast::server {

GrpcListener::GrpcListener(const std::string& address, unsigned short port, ConnectionLimits limits)
    : listener_(io_, address, port, "gRPC"), limits_(std::move(limits)) {}

GrpcListener::~GrpcListener() { stop(); }

void GrpcListener::start(grpc::experimental::ExternalConnectionAcceptor& acceptor) {
  listener_.start([this, &acceptor, listening = listener_.native_handle()](
                      boost::asio::ip::tcp::socket socket, boost::asio::ip::address client) {
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
    // A number in the table is taken again only once gRPC closed the connection that had it.
    handed_[fd] = {status.st_dev, status.st_ino, std::move(slot)};
    grpc::experimental::ExternalConnectionAcceptor::NewConnectionParameters connection;
    connection.listener_fd = listening;
    connection.fd = fd;
    acceptor.HandleNewConnection(&connection);
  });
  thread_ = std::thread([this] { io_.run(); });
}

std::shared_ptr<ConnectionLimits::Slot> GrpcListener::admit(
    const boost::asio::ip::address& client) {
  if (auto slot = limits_.admit(client)) return slot;
  forget_closed(client);
  return limits_.admit(client);
}

void GrpcListener::forget_closed(const boost::asio::ip::address& client) {
  std::erase_if(handed_, [&client](const auto& entry) {
    const auto& [fd, handed] = entry;
    if (handed.slot->address() != client) return false;
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

}  // namespace fluidcast::server

#include "grpc/grpc_listener.h"

#include <grpcpp/server_posix.h>

namespace fluidcast::server {

GrpcListener::GrpcListener(const std::string& address, unsigned short port)
    : listener_(io_, address, port, "gRPC") {}

GrpcListener::~GrpcListener() { stop(); }

void GrpcListener::start(grpc::Server& server) {
  listener_.start([&server](boost::asio::ip::tcp::socket socket) {
    socket.set_option(boost::asio::ip::tcp::no_delay(true));
    grpc::AddInsecureChannelFromFd(&server, socket.release());
  });
  thread_ = std::thread([this] { io_.run(); });
}

void GrpcListener::stop() {
  io_.stop();
  if (thread_.joinable()) thread_.join();
}

}  // namespace fluidcast::server

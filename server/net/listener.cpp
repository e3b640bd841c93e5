#include "net/listener.h"

#include <spdlog/spdlog.h>
#include <unistd.h>

#include <boost/asio/strand.hpp>
#include <cerrno>
#include <stdexcept>

namespace fluidcast::server {
namespace {

using tcp = boost::asio::ip::tcp;

// Whether the process could open one more descriptor now.
bool descriptor_free() {
  const int probe = dup(STDIN_FILENO);
  if (probe < 0) return errno != EMFILE && errno != ENFILE;
  ::close(probe);
  return true;
}

// An accept that failed for want of descriptors or memory: accepting again at once would fail the
// same way, in a loop. ENFILE (the system's file table full) has no Asio name.
bool out_of_resources(const boost::system::error_code& error) {
  return error == boost::asio::error::no_descriptors ||
         error == boost::system::error_code(ENFILE, boost::system::system_category()) ||
         error == boost::asio::error::no_buffer_space || error == boost::asio::error::no_memory;
}

}  // namespace

Listener::Listener(boost::asio::io_context& io, const std::string& address, unsigned short port,
                   std::string what)
    : what_(std::move(what)), io_(&io), acceptor_(io), retry_(io) {
  try {
    const tcp::endpoint endpoint(boost::asio::ip::make_address(address), port);
    acceptor_.open(endpoint.protocol());
    // Over a closed connection's TIME_WAIT, not over another listener (no SO_REUSEPORT).
    acceptor_.set_option(boost::asio::socket_base::reuse_address(true));
    acceptor_.bind(endpoint);
    acceptor_.listen();
    port_ = acceptor_.local_endpoint().port();
  } catch (const std::exception& e) {
    throw std::runtime_error(what_ + ": cannot listen on " + address + ":" + std::to_string(port) +
                             ": " + e.what());
  }
}

void Listener::start(Take take) {
  take_ = std::move(take);
  accept();
}

void Listener::close() {
  boost::system::error_code ignored;
  retry_.cancel();
  acceptor_.close(ignored);
}

void Listener::accept() {
  acceptor_.async_accept(boost::asio::make_strand(*io_), [this](boost::system::error_code error,
                                                                tcp::socket socket) {
    if (!acceptor_.is_open()) return;
    if (out_of_resources(error)) {
      if (accepting_.exchange(false)) {
        spdlog::warn("{}: cannot accept connections: {}; trying again every {} ms", what_,
                     error.message(), kRetry.count());
      }
      retry_.expires_after(kRetry);
      retry_.async_wait([this](boost::system::error_code cancelled) {
        if (cancelled) return;
        if (descriptor_free() && !accepting_.exchange(true)) {
          spdlog::info("{}: descriptors are back: accepting connections again", what_);
        }
        accept();
      });
      return;
    }
    if (!error) {
      if (!accepting_.exchange(true)) spdlog::info("{}: accepting connections again", what_);
      boost::system::error_code gone;
      boost::asio::ip::address client = socket.remote_endpoint(gone).address();
      if (client.is_v6() && client.to_v6().is_v4_mapped()) {
        client = boost::asio::ip::make_address_v4(boost::asio::ip::v4_mapped, client.to_v6());
      }
      if (!gone) take_(std::move(socket), client);
    }
    accept();
  });
}

}  // namespace fluidcast::server

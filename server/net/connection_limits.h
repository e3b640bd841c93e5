// A port's open connections, in all and from each address, against the operator's limits
// (ServerLimits::max_connections, max_connections_per_address): a connection over either is
// closed as soon as it is accepted, before it costs more than its descriptor. The HTTP port and
// the gRPC port count theirs each.
#pragma once

#include <boost/asio/ip/address.hpp>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>

namespace fluidcast::server {

class ConnectionLimits {
  struct Tally {
    std::mutex mutex;
    std::uint32_t total = 0;
    std::uint32_t awaiting = 0;  // of total, those waiting for their client
    std::map<boost::asio::ip::address, std::uint32_t> per_address;
  };

 public:
  // One connection, counted while it lives (it goes with the connection, whichever object holds
  // it: the request reader, then a WebSocket).
  class Slot {
   public:
    ~Slot();
    Slot(const Slot&) = delete;
    Slot& operator=(const Slot&) = delete;
    const boost::asio::ip::address& address() const { return address_; }
    // Whether the connection waits for its client's next bytes (a request, a TLS handshake; a
    // new connection does): one a stopping server may cut without losing anything (busy()).
    void set_awaiting(bool awaiting);

   private:
    friend class ConnectionLimits;  // admit() makes them: a slot made elsewhere was never counted
    Slot(std::shared_ptr<Tally> tally, boost::asio::ip::address address)
        : tally_(std::move(tally)), address_(std::move(address)) {}

    std::shared_ptr<Tally> tally_;
    boost::asio::ip::address address_;
    bool awaiting_ = true;  // under tally_->mutex
  };

  ConnectionLimits(std::uint32_t total, std::uint32_t per_address)
      : most_total_(total), most_per_address_(per_address) {}

  // A slot for a connection from `address`; null when it would pass a limit.
  std::shared_ptr<Slot> admit(const boost::asio::ip::address& address);
  std::uint32_t open() const;
  // Open connections that are not waiting for their client: answering it, or a WebSocket.
  std::uint32_t busy() const;

 private:
  std::uint32_t most_total_, most_per_address_;
  std::shared_ptr<Tally> tally_ = std::make_shared<Tally>();
};

}  // namespace fluidcast::server

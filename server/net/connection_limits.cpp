#include "net/connection_limits.h"

namespace fluidcast::server {

ConnectionLimits::Slot::~Slot() {
  std::lock_guard lock(tally_->mutex);
  --tally_->total;
  if (awaiting_) --tally_->awaiting;
  if (--tally_->per_address[address_] == 0) tally_->per_address.erase(address_);
}

std::shared_ptr<ConnectionLimits::Slot> ConnectionLimits::admit(
    const boost::asio::ip::address& address) {
  std::lock_guard lock(tally_->mutex);
  std::uint32_t& from_address = tally_->per_address[address];
  if (tally_->total >= most_total_ || from_address >= most_per_address_) {
    if (from_address == 0) tally_->per_address.erase(address);
    return nullptr;
  }
  ++tally_->total;
  ++tally_->awaiting;
  ++from_address;
  return std::shared_ptr<Slot>(new Slot(tally_, address));
}

void ConnectionLimits::Slot::set_awaiting(bool awaiting) {
  std::lock_guard lock(tally_->mutex);
  if (awaiting == awaiting_) return;
  awaiting_ = awaiting;
  awaiting ? ++tally_->awaiting : --tally_->awaiting;
}

std::uint32_t ConnectionLimits::open() const {
  std::lock_guard lock(tally_->mutex);
  return tally_->total;
}

std::uint32_t ConnectionLimits::busy() const {
  std::lock_guard lock(tally_->mutex);
  return tally_->total - tally_->awaiting;
}

}  // namespace fluidcast::server

// gRPC's peer strings to the address that per-address limits count.
#include "grpc/peer_address.h"

#include <gtest/gtest.h>

namespace fluidcast::server {
namespace {

TEST(PeerAddressTest, ThePortIsDroppedAndTheAddressKept) {
  EXPECT_EQ(peer_address("ipv4:10.0.0.7:51234"), "10.0.0.7");
  EXPECT_EQ(peer_address("ipv6:[::1]:51234"), "::1");
  EXPECT_EQ(peer_address("ipv6:%5B2001:db8::2%5D:443"), "2001:db8::2");
  EXPECT_EQ(peer_address("ipv6:[::ffff:10.0.0.7]:51234"), "10.0.0.7");
  EXPECT_EQ(peer_address("ipv6:%5B::ffff:10.0.0.7%5D:51234"), "10.0.0.7");
  EXPECT_EQ(peer_address("ipv6:[::ffff:a00:7]:51234"), "::ffff:a00:7");
  EXPECT_EQ(peer_address("unix:/run/fluidcast.sock"), "unix:/run/fluidcast.sock");
  EXPECT_EQ(peer_address("odd"), "odd");
}

}  // namespace
}  // namespace fluidcast::server

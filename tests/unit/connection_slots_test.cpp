// A port's connection slots: the limits in all and from one address, and which open connections
// are busy (answering their client, or a WebSocket) rather than waiting for it.
#include <gtest/gtest.h>

#include "net/connection_limits.h"

namespace fluidcast::server {
namespace {

const auto kHere = boost::asio::ip::make_address("10.0.0.7");
const auto kThere = boost::asio::ip::make_address("10.0.0.8");

TEST(ConnectionSlotsTest, AConnectionOverEitherLimitIsRefusedAndASlotGivesItsPlaceBack) {
  ConnectionLimits limits(3, 2);
  auto first = limits.admit(kHere);
  auto second = limits.admit(kHere);
  ASSERT_TRUE(first && second);
  EXPECT_FALSE(limits.admit(kHere));  // two from one address
  auto third = limits.admit(kThere);
  ASSERT_TRUE(third);
  EXPECT_FALSE(limits.admit(boost::asio::ip::make_address("10.0.0.9")));  // three in all
  EXPECT_EQ(limits.open(), 3u);
  first.reset();
  EXPECT_EQ(limits.open(), 2u);
  EXPECT_TRUE(limits.admit(kHere));
}

TEST(ConnectionSlotsTest, OnlyConnectionsNotWaitingForTheirClientAreBusy) {
  ConnectionLimits limits(10, 10);
  auto waiting = limits.admit(kHere);  // a new connection waits for its first bytes
  auto answering = limits.admit(kHere);
  EXPECT_EQ(limits.busy(), 0u);
  answering->set_awaiting(false);
  answering->set_awaiting(false);  // said twice, counted once
  EXPECT_EQ(limits.busy(), 1u);
  waiting.reset();
  EXPECT_EQ(limits.busy(), 1u);
  answering.reset();  // a busy connection that closes is no longer counted
  EXPECT_EQ(limits.busy(), 0u);
  EXPECT_EQ(limits.open(), 0u);
  auto again = limits.admit(kThere);
  again->set_awaiting(false);
  again->set_awaiting(true);
  EXPECT_EQ(limits.busy(), 0u);
}

}  // namespace
}  // namespace fluidcast::server

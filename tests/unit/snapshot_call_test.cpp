// Snapshot calls one at a time per key: a second call with a key whose call is under way is
// refused until the first is done; other keys are not held up.
#include "grpc/snapshot_call.h"

#include <gtest/gtest.h>

namespace fluidcast::server {
namespace {

TEST(KeysInFlightTest, AKeyHasOneCallAtATime) {
  KeysInFlight keys;
  EXPECT_TRUE(keys.take("view-key"));
  EXPECT_FALSE(keys.take("view-key"));
  EXPECT_TRUE(keys.take("control-key"));
  keys.release("view-key");
  EXPECT_TRUE(keys.take("view-key"));
  EXPECT_FALSE(keys.take("control-key"));
}

}  // namespace
}  // namespace fluidcast::server

// Snapshot calls one at a time per key: a second call with a key whose call is under way is
// refused until the first is answered, and a third while two answers are still being sent;
// other keys are not held up.
#include "grpc/snapshot_call.h"

#include <gtest/gtest.h>

namespace fluidcast::server {
namespace {

TEST(KeysInFlightTest, AKeyHasOneCallAtATime) {
  KeysInFlight keys;
  EXPECT_TRUE(keys.take("view-key"));
  EXPECT_FALSE(keys.take("view-key"));
  EXPECT_TRUE(keys.take("control-key"));
  keys.answered("view-key");
  EXPECT_TRUE(keys.take("view-key"));
  EXPECT_FALSE(keys.take("control-key"));
}

// A client that never reads its answers has at most two of them held in the server's memory.
TEST(KeysInFlightTest, AnswersNotYetSentHoldTheKeyFromTheSecondOn) {
  KeysInFlight keys;
  for (int answer = 0; answer < KeysInFlight::kUnreadAnswers; ++answer) {
    ASSERT_TRUE(keys.take("view-key")) << "answer " << answer;
    keys.answered("view-key");
  }
  EXPECT_FALSE(keys.take("view-key"));
  EXPECT_TRUE(keys.take("control-key"));
  keys.sent("view-key");
  EXPECT_TRUE(keys.take("view-key"));
  keys.answered("view-key");
  EXPECT_FALSE(keys.take("view-key"));
  for (int answer = 0; answer < KeysInFlight::kUnreadAnswers; ++answer) keys.sent("view-key");
  EXPECT_TRUE(keys.take("view-key"));
}

}  // namespace
}  // namespace fluidcast::server

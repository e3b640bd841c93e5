// Snapshot calls one at a time per key: a second call with a key whose call is under way is
// refused until the first is answered; a call that finds two answers of its key still being sent
// waits for one of them to go out; other keys are not held up.
#include "grpc/snapshot_call.h"

#include <gtest/gtest.h>

namespace fluidcast::server {
namespace {

TEST(KeysInFlightTest, AKeyHasOneCallAtATime) {
  KeysInFlight keys;
  int gone_on = 0;
  const auto go_on = [&gone_on] { ++gone_on; };
  EXPECT_TRUE(keys.take("view-key", go_on));
  EXPECT_FALSE(keys.take("view-key", go_on));
  EXPECT_TRUE(keys.take("control-key", go_on));
  EXPECT_EQ(gone_on, 2);
  keys.answered("view-key");
  EXPECT_TRUE(keys.take("view-key", go_on));
  EXPECT_FALSE(keys.take("control-key", go_on));
  EXPECT_EQ(gone_on, 3);
}

// A client that never reads its answers has at most two of them held in the server's memory, and
// one more call waiting; a client that reads each answer before calling again never waits long.
TEST(KeysInFlightTest, ACallWaitsWhileTwoAnswersOfItsKeyAreBeingSent) {
  KeysInFlight keys;
  int gone_on = 0;
  const auto go_on = [&gone_on] { ++gone_on; };
  for (int answer = 0; answer < KeysInFlight::kUnreadAnswers; ++answer) {
    ASSERT_TRUE(keys.take("view-key", go_on)) << "answer " << answer;
    keys.answered("view-key");
  }
  ASSERT_EQ(gone_on, KeysInFlight::kUnreadAnswers);

  bool waited_on = false;
  EXPECT_TRUE(keys.take("view-key", [&waited_on] { waited_on = true; }));
  EXPECT_FALSE(waited_on);
  EXPECT_FALSE(keys.take("view-key", go_on)) << "the waiting call holds the key";
  EXPECT_TRUE(keys.take("control-key", go_on));
  EXPECT_EQ(gone_on, KeysInFlight::kUnreadAnswers + 1);

  keys.sent("view-key");
  EXPECT_TRUE(waited_on);
  keys.answered("view-key");
  EXPECT_TRUE(keys.take("view-key", go_on));
  EXPECT_EQ(gone_on, KeysInFlight::kUnreadAnswers + 1) << "two answers are being sent again";
  keys.sent("view-key");
  EXPECT_EQ(gone_on, KeysInFlight::kUnreadAnswers + 2);
}

}  // namespace
}  // namespace fluidcast::server

// Snapshot calls one at a time per key and connection: a second call with the same key on the same
// connection is refused until the first is answered; a call that finds two answers of its key and
// connection still being sent waits for one of them to go out; other keys and other connections
// are not held up.
#include "grpc/snapshot_call.h"

#include <gtest/gtest.h>

namespace fluidcast::server {
namespace {

const SnapshotCaller kViewer{"view-key", "ipv4:192.0.2.1:50000"};
const SnapshotCaller kController{"control-key", "ipv4:192.0.2.1:50000"};
const SnapshotCaller kOtherViewer{"view-key", "ipv4:192.0.2.7:41000"};

TEST(SnapshotSlotsTest, AKeyHasOneCallAtATimeOnAConnection) {
  SnapshotSlots slots;
  int gone_on = 0;
  const auto go_on = [&gone_on] { ++gone_on; };
  EXPECT_TRUE(slots.take(kViewer, go_on));
  EXPECT_FALSE(slots.take(kViewer, go_on));
  EXPECT_TRUE(slots.take(kController, go_on));
  EXPECT_TRUE(slots.take(kOtherViewer, go_on)) << "viewers sharing the view key";
  EXPECT_EQ(gone_on, 3);
  slots.answered(kViewer);
  EXPECT_TRUE(slots.take(kViewer, go_on));
  EXPECT_FALSE(slots.take(kController, go_on));
  EXPECT_EQ(gone_on, 4);
}

// A client that never reads its answers has at most two of them held in the server's memory, and
// one more call waiting; a client that reads each answer before calling again never waits long.
TEST(SnapshotSlotsTest, ACallWaitsWhileTwoAnswersOfItsKeyAndConnectionAreBeingSent) {
  SnapshotSlots slots;
  int gone_on = 0;
  const auto go_on = [&gone_on] { ++gone_on; };
  for (int answer = 0; answer < SnapshotSlots::kUnreadAnswers; ++answer) {
    ASSERT_TRUE(slots.take(kViewer, go_on)) << "answer " << answer;
    slots.answered(kViewer);
  }
  ASSERT_EQ(gone_on, SnapshotSlots::kUnreadAnswers);

  bool waited_on = false;
  EXPECT_TRUE(slots.take(kViewer, [&waited_on] { waited_on = true; }));
  EXPECT_FALSE(waited_on);
  EXPECT_FALSE(slots.take(kViewer, go_on)) << "the waiting call holds the slot";
  EXPECT_TRUE(slots.take(kController, go_on));
  EXPECT_TRUE(slots.take(kOtherViewer, go_on)) << "another connection's answers are its own";
  EXPECT_EQ(gone_on, SnapshotSlots::kUnreadAnswers + 2);

  slots.sent(kOtherViewer);  // nothing of kOtherViewer's was being sent: no effect
  EXPECT_FALSE(waited_on);
  slots.sent(kViewer);
  EXPECT_TRUE(waited_on);
  slots.answered(kViewer);
  EXPECT_TRUE(slots.take(kViewer, go_on));
  EXPECT_EQ(gone_on, SnapshotSlots::kUnreadAnswers + 2) << "two answers are being sent again";
  slots.sent(kViewer);
  EXPECT_EQ(gone_on, SnapshotSlots::kUnreadAnswers + 3);
}

}  // namespace
}  // namespace fluidcast::server

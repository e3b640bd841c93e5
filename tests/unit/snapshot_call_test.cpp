// Snapshot calls one at a time per key and connection: a second call with the same key on the same
// connection is refused until the first is answered; a call that finds two answers with its key to
// its address still being sent (or worked on) waits for one of them to go out, whichever of the
// address's connections it comes on; other keys and other addresses are not held up.
#include "grpc/snapshot_call.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace fluidcast::server {
namespace {

bool taken(SnapshotSlots::Take take) { return take == SnapshotSlots::Take::taken; }

const SnapshotCaller kViewer{"view-key", "ipv4:192.0.2.1:50000"};
const SnapshotCaller kController{"control-key", "ipv4:192.0.2.1:50000"};
const SnapshotCaller kOtherViewer{"view-key", "ipv4:192.0.2.7:41000"};
const SnapshotCaller kViewersOtherConnection{"view-key", "ipv4:192.0.2.1:50001"};

TEST(SnapshotSlotsTest, AKeyHasOneCallAtATimeOnAConnection) {
  SnapshotSlots slots;
  int gone_on = 0;
  const auto go_on = [&gone_on] { ++gone_on; };
  EXPECT_TRUE(taken(slots.take(kViewer, go_on)));
  EXPECT_FALSE(taken(slots.take(kViewer, go_on)));
  EXPECT_TRUE(taken(slots.take(kController, go_on)));
  EXPECT_TRUE(taken(slots.take(kOtherViewer, go_on))) << "viewers sharing the view key";
  EXPECT_EQ(gone_on, 3);
  slots.answered(kViewer);
  EXPECT_TRUE(taken(slots.take(kViewer, go_on)));
  EXPECT_FALSE(taken(slots.take(kController, go_on)));
  EXPECT_EQ(gone_on, 4);
}

// A client that never reads its answers has at most two of them held in the server's memory, and
// one more call waiting; a client that reads each answer before calling again never waits long.
TEST(SnapshotSlotsTest, ACallWaitsWhileTwoAnswersOfItsKeyAndConnectionAreBeingSent) {
  SnapshotSlots slots;
  int gone_on = 0;
  const auto go_on = [&gone_on] { ++gone_on; };
  for (int answer = 0; answer < SnapshotSlots::kUnreadAnswers; ++answer) {
    ASSERT_TRUE(taken(slots.take(kViewer, go_on))) << "answer " << answer;
    slots.answered(kViewer);
  }
  ASSERT_EQ(gone_on, SnapshotSlots::kUnreadAnswers);

  bool waited_on = false;
  EXPECT_TRUE(taken(slots.take(kViewer, [&waited_on] { waited_on = true; })));
  EXPECT_FALSE(waited_on);
  EXPECT_FALSE(taken(slots.take(kViewer, go_on))) << "the waiting call holds the slot";
  EXPECT_TRUE(taken(slots.take(kController, go_on)));
  EXPECT_TRUE(taken(slots.take(kOtherViewer, go_on))) << "another address's answers are its own";
  EXPECT_EQ(gone_on, SnapshotSlots::kUnreadAnswers + 2);

  slots.sent(kOtherViewer);  // nothing of kOtherViewer's was being sent: no effect
  EXPECT_FALSE(waited_on);
  slots.sent(kViewer);
  EXPECT_TRUE(waited_on);
  slots.answered(kViewer);
  EXPECT_TRUE(taken(slots.take(kViewer, go_on)));
  EXPECT_EQ(gone_on, SnapshotSlots::kUnreadAnswers + 2) << "two answers are being sent again";
  slots.sent(kViewer);
  EXPECT_EQ(gone_on, SnapshotSlots::kUnreadAnswers + 3);
}

// One client's many connections share its address's two answers: 64 connections that never read
// would otherwise hold 64 times as many in the server's memory.
TEST(SnapshotSlotsTest, AnAddressHasTwoAnswersOfAKeyHeldWhateverItsConnections) {
  SnapshotSlots slots;
  int gone_on = 0;
  const auto go_on = [&gone_on] { ++gone_on; };
  ASSERT_TRUE(taken(slots.take(kViewer, go_on)));
  slots.answered(kViewer);
  ASSERT_TRUE(taken(slots.take(kViewersOtherConnection, go_on)));  // worked on, not yet answered
  ASSERT_EQ(gone_on, 2);

  std::vector<int> order;
  const SnapshotCaller third{"view-key", "ipv4:192.0.2.1:50002"};
  const SnapshotCaller fourth{"view-key", "ipv4:192.0.2.1:50003"};
  EXPECT_TRUE(taken(slots.take(third, [&order] { order.push_back(3); })));
  EXPECT_TRUE(taken(slots.take(fourth, [&order] { order.push_back(4); })));
  EXPECT_TRUE(order.empty()) << "two are held for the address already";
  EXPECT_TRUE(taken(slots.take(kOtherViewer, go_on))) << "another address is not held up";
  EXPECT_EQ(gone_on, 3);

  slots.sent(kViewer);
  EXPECT_EQ(order, std::vector<int>{3}) << "the call that waited longest goes first, alone";
  slots.answered(kViewersOtherConnection);
  slots.sent(kViewersOtherConnection);
  EXPECT_EQ(order, (std::vector<int>{3, 4}));
}

// Calls waiting for an address's unread answers each hold their request (a PutSnapshot's is the
// whole fluid): past kMostWaiting of them the next is refused, and leaves no slot taken.
TEST(SnapshotSlotsTest, AnAddressHasAFewCallsOfAKeyWaitingAndNoMore) {
  SnapshotSlots slots;
  int gone_on = 0;
  const auto go_on = [&gone_on] { ++gone_on; };
  const auto connection = [](int port) {
    return SnapshotCaller{"control-key", "ipv4:192.0.2.1:" + std::to_string(port)};
  };
  int port = 50000;
  for (int answer = 0; answer < SnapshotSlots::kUnreadAnswers; ++answer, ++port) {
    ASSERT_TRUE(taken(slots.take(connection(port), go_on)));
    slots.answered(connection(port));
  }
  const int first_waiting = port;
  for (std::size_t waiting = 0; waiting < SnapshotSlots::kMostWaiting; ++waiting, ++port) {
    ASSERT_TRUE(taken(slots.take(connection(port), go_on)));
  }
  EXPECT_EQ(slots.take(connection(port), go_on), SnapshotSlots::Take::too_many_waiting);
  EXPECT_TRUE(taken(slots.take(kOtherViewer, go_on))) << "another address is not held up";
  EXPECT_EQ(gone_on, SnapshotSlots::kUnreadAnswers + 1);

  slots.sent(connection(50000));  // the longest waiting goes on: one place is free
  EXPECT_EQ(gone_on, SnapshotSlots::kUnreadAnswers + 2);
  slots.answered(connection(first_waiting));
  EXPECT_TRUE(taken(slots.take(connection(port), go_on))) << "the refused call took no slot";
}

}  // namespace
}  // namespace fluidcast::server

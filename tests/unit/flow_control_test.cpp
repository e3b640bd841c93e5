// A viewer's flow control on a clock the test sets: the rate it asked for, throttling when frames
// go unacknowledged, the round trip, and adaptive quality and size, each step of it.
#include "session/flow_control.h"

#include <gtest/gtest.h>

namespace fluidcast::server {
namespace {

using std::chrono::milliseconds;
using std::chrono::seconds;

class FlowControlTest : public testing::Test {
 protected:
  FlowControlTest() {
    flow.ask_size({640, 480});
    flow.ask(30, 80, true);
  }
  // Renders and hands over a frame now; returns its sequence.
  std::uint64_t frame() {
    flow.rendered(now);
    return flow.produced(now);
  }
  // One frame acknowledged after `round_trip`, then the clock past the adaptation interval.
  void round_trip(milliseconds round_trip) {
    const std::uint64_t sequence = frame();
    now += round_trip;
    flow.acknowledge(sequence, now);
    now += FlowControl::kAdaptEvery;
  }

  // Past the first adaptation interval from the clock's zero, where the last adaptation starts.
  Clock::time_point now = Clock::time_point{} + std::chrono::hours(1);
  FlowControl flow{now};
};

TEST_F(FlowControlTest, FramesFollowTheRateAskedFor) {
  EXPECT_TRUE(flow.due(now));
  flow.acknowledge(frame(), now);  // a new rate starts with this frame
  EXPECT_TRUE(flow.due(now));
  flow.acknowledge(frame(), now);
  EXPECT_FALSE(flow.due(now + milliseconds(30)));
  EXPECT_TRUE(flow.due(now + milliseconds(34)));  // 1/30 s
  flow.ask(10, 80, true);  // a new rate starts now, not after the old interval
  EXPECT_TRUE(flow.due(now + milliseconds(1)));
  flow.acknowledge(frame(), now);
  flow.acknowledge(frame(), now);
  EXPECT_FALSE(flow.due(now + milliseconds(90)));
  EXPECT_TRUE(flow.due(now + milliseconds(101)));
}

TEST_F(FlowControlTest, AViewerThatDoesNotAcknowledgeGetsAFrameASecondAfterItsThird) {
  for (std::uint64_t k = 0; k < FlowControl::kMaxFramesInFlight; ++k) {
    ASSERT_TRUE(flow.due(now)) << k;
    frame();
    now += milliseconds(34);
  }
  EXPECT_TRUE(flow.throttled());
  EXPECT_FALSE(flow.due(now + milliseconds(500)));
  EXPECT_TRUE(flow.due(now + FlowControl::kThrottledFrameEvery));
  flow.acknowledge(3, now);
  EXPECT_FALSE(flow.throttled());
  EXPECT_TRUE(flow.due(now));
}

// A throttled viewer's frames held back are counted once a frame interval (30 a second here),
// however often the server ticks (120 a second here), and not at all while it keeps up.
TEST_F(FlowControlTest, FramesHeldBackAreCountedByTheRateNotByTheTick) {
  const auto skipped_in_a_second = [&] {
    int skipped = 0;
    for (int tick = 0; tick < 120; ++tick) {
      if (!flow.due(now) && flow.skips_frame(now)) ++skipped;
      now += std::chrono::microseconds(8333);
    }
    return skipped;
  };
  EXPECT_EQ(skipped_in_a_second(), 0);
  for (std::uint64_t k = 0; k < FlowControl::kMaxFramesInFlight; ++k) frame();
  ASSERT_TRUE(flow.throttled());
  const int skipped = skipped_in_a_second();
  EXPECT_GE(skipped, 28);
  EXPECT_LE(skipped, 31);
}

TEST_F(FlowControlTest, AcknowledgementsOfFramesNotSentOrAlreadyAcknowledgedAreIgnored) {
  const std::uint64_t sequence = frame();
  flow.acknowledge(sequence + 5, now + milliseconds(10));
  EXPECT_FALSE(flow.round_trip_ms());
  flow.acknowledge(sequence, now + milliseconds(40));
  EXPECT_DOUBLE_EQ(*flow.round_trip_ms(), 40.0);
  flow.acknowledge(sequence, now + milliseconds(90));
  EXPECT_DOUBLE_EQ(*flow.round_trip_ms(), 40.0);
}

// A frame acknowledged once as many more have been sent as the record of send times holds (64):
// its send time is gone, so its round trip is not known, and the last one measured stands.
TEST_F(FlowControlTest, AnAcknowledgementTooLateForTheRecordMeasuresNothing) {
  const std::uint64_t first = frame();
  const std::uint64_t second = frame();
  flow.acknowledge(first, now + milliseconds(40));
  for (int k = 0; k < 64; ++k) {
    now += milliseconds(1);
    frame();
  }
  flow.acknowledge(second, now + milliseconds(5));
  EXPECT_DOUBLE_EQ(*flow.round_trip_ms(), 40.0);
}

TEST_F(FlowControlTest, FallingBehindLowersQualityThenSizeAndKeepingUpRaisesThemBack) {
  round_trip(milliseconds(200));
  EXPECT_EQ(flow.jpeg_quality(), 70);
  for (int k = 0; k < 10; ++k) round_trip(milliseconds(200));
  EXPECT_EQ(flow.jpeg_quality(), FlowControl::kLowestAdaptiveQuality);
  EXPECT_LT(flow.render_size().height, 480u);
  EXPECT_GE(flow.render_size().height, FlowControl::kSmallestAdaptiveHeight * 3 / 4);
  for (int k = 0; k < 40; ++k) round_trip(milliseconds(10));
  EXPECT_EQ(flow.render_size(), (FlowControl::Size{640, 480}));  // the size first
  EXPECT_EQ(flow.jpeg_quality(), 80);                            // then quality
}

// Frames queued behind the viewer mean it is behind, however short the round trip of the one it
// acknowledged.
TEST_F(FlowControlTest, FramesQueuedBehindTheViewerLowerQualityHoweverShortTheRoundTrip) {
  const std::uint64_t first = frame();
  for (std::uint64_t k = 0; k < FlowControl::kMaxFramesInFlight; ++k) frame();
  flow.acknowledge(first, now + milliseconds(10));
  ASSERT_TRUE(flow.throttled());
  EXPECT_EQ(flow.jpeg_quality(), 70);
}

// At most one step of adaptation a kAdaptEvery, however many acknowledgements arrive.
TEST_F(FlowControlTest, AdaptationStepsAtMostOnceAnInterval) {
  const std::uint64_t first = frame();
  frame();
  frame();
  for (std::uint64_t k = 0; k < 3; ++k) flow.acknowledge(first + k, now + milliseconds(200 + k));
  EXPECT_EQ(flow.jpeg_quality(), 70);
}

// Quality comes back to the one asked, not past it, whatever steps it went down and up by (35 plus
// steps of 5 never lands on 83: without the cap it would be 85).
TEST_F(FlowControlTest, QualityComesBackToTheOneAskedExactly) {
  flow.ask(30, 83, true);
  for (int k = 0; k < 12; ++k) round_trip(milliseconds(200));
  ASSERT_EQ(flow.jpeg_quality(), FlowControl::kLowestAdaptiveQuality);
  for (int k = 0; k < 40; ++k) round_trip(milliseconds(10));
  EXPECT_EQ(flow.jpeg_quality(), 83);
}

TEST_F(FlowControlTest, InBetweenNothingChangesAndWithoutAdaptationNeither) {
  round_trip(milliseconds(80));
  EXPECT_EQ(flow.jpeg_quality(), 80);
  flow.ask(30, 90, false);
  round_trip(milliseconds(500));
  EXPECT_EQ(flow.jpeg_quality(), 90);
  EXPECT_EQ(flow.render_size(), (FlowControl::Size{640, 480}));
}

TEST_F(FlowControlTest, AskingAgainStartsFromWhatWasAsked) {
  for (int k = 0; k < 12; ++k) round_trip(milliseconds(200));
  ASSERT_LT(flow.render_size().width, 640u);
  flow.ask_size({320, 240});
  EXPECT_EQ(flow.render_size(), (FlowControl::Size{320, 240}));
  flow.ask(30, 0, true);
  EXPECT_EQ(flow.jpeg_quality(), FlowControl::kDefaultQuality);
  for (int k = 0; k < 12; ++k) round_trip(milliseconds(200));
  ASSERT_LT(flow.render_size().width, 320u);
  flow.ask(30, 80, true);
  EXPECT_EQ(flow.render_size(), (FlowControl::Size{320, 240}));
}

TEST_F(FlowControlTest, TheWaitForAFrameRunsFromJoiningThenFromTheLastFrame) {
  EXPECT_EQ(flow.since_rendered(now + seconds(2)), seconds(2));  // nothing rendered yet
  frame();
  EXPECT_EQ(flow.since_rendered(now + seconds(1)), seconds(1));
  flow.ask(60, 80, true);  // a new rate: due at once, but the wait goes on
  EXPECT_EQ(flow.since_rendered(now + seconds(1)), seconds(1));
}

}  // namespace
}  // namespace fluidcast::server

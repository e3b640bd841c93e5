#include "session/outgoing_messages.h"

#include <gtest/gtest.h>

#include <chrono>
#include <thread>

namespace fluidcast::server {
namespace {

std::shared_ptr<const v1::ServerMessage> frame(std::uint64_t sequence) {
  auto message = std::make_shared<v1::ServerMessage>();
  message->mutable_frame()->set_sequence(sequence);
  return message;
}

std::shared_ptr<const v1::ServerMessage> welcome() {
  auto message = std::make_shared<v1::ServerMessage>();
  message->mutable_welcome()->set_viewer_id(7);
  return message;
}

std::shared_ptr<const v1::ServerMessage> state(double time) {
  auto message = std::make_shared<v1::ServerMessage>();
  message->mutable_state()->set_time(time);
  return message;
}

// States (answers to StateRequest) wait like frames: only the newest, after control messages and
// before the frame, and none once the stream ends.
TEST(OutgoingMessagesTest, OnlyTheNewestStateWaits) {
  OutgoingMessages queue;
  queue.push(frame(1));
  queue.push(state(1.0));
  queue.push(state(2.0));
  queue.push(welcome());
  EXPECT_TRUE(queue.next()->has_welcome());
  EXPECT_EQ(queue.next()->state().time(), 2.0);
  EXPECT_TRUE(queue.next()->has_frame());
  EXPECT_FALSE(queue.next());
  queue.push(state(3.0));
  queue.stop_frames();
  EXPECT_FALSE(queue.next());
  queue.push(state(4.0));  // and none pushed after the end
  EXPECT_FALSE(queue.next());
}

// Changes of the session's state wait the same way: only the newest (a viewer that reads slowly
// while others keep pausing holds one), before the frame drawn after the change. A state (the
// answer to a StateRequest) from before the change is dropped: kept as the newest, it would be
// handed back as the session's fluid.
TEST(OutgoingMessagesTest, OnlyTheNewestSessionStateWaitsAndDropsTheStateBeforeIt) {
  OutgoingMessages queue;
  const auto session = [](bool paused) {
    auto message = std::make_shared<v1::ServerMessage>();
    message->mutable_session()->set_paused(paused);
    return std::shared_ptr<const v1::ServerMessage>(message);
  };
  queue.push(frame(1));
  queue.push(state(1.0));
  for (int k = 0; k <= 1000; ++k) queue.push(session(k % 2 == 1));
  queue.push(state(2.0));
  const auto newest = queue.next();
  ASSERT_TRUE(newest->has_session());
  EXPECT_FALSE(newest->session().paused());
  EXPECT_EQ(queue.next()->state().time(), 2.0);
  EXPECT_TRUE(queue.next()->has_frame());
  EXPECT_FALSE(queue.next());
  queue.push(state(3.0));
  queue.push(session(true));
  EXPECT_TRUE(queue.next()->has_session());
  EXPECT_FALSE(queue.next()) << "the state from before the change was kept";
  queue.push(session(false));
  queue.stop_frames();
  EXPECT_FALSE(queue.next());
}

TEST(OutgoingMessagesTest, ControlFirstThenOnlyTheNewestFrame) {
  OutgoingMessages queue;
  EXPECT_FALSE(queue.next());
  EXPECT_TRUE(queue.push(frame(1)));
  EXPECT_FALSE(queue.push(frame(3)));  // replaces 1
  EXPECT_FALSE(queue.push(frame(2)));  // older than 3: dropped
  const auto hello = welcome();
  EXPECT_TRUE(queue.push(hello));
  EXPECT_TRUE(queue.next() == hello);
  EXPECT_EQ(queue.next()->frame().sequence(), 3u);
  EXPECT_FALSE(queue.next());
  EXPECT_FALSE(queue.push(frame(3)));  // already taken
  EXPECT_TRUE(queue.push(frame(4)));
  EXPECT_EQ(queue.next()->frame().sequence(), 4u);
}

TEST(OutgoingMessagesTest, AnEndingStreamDropsFramesButNotControl) {
  OutgoingMessages queue;
  EXPECT_TRUE(queue.push(frame(1)));
  queue.stop_frames();
  EXPECT_FALSE(queue.push(frame(2)));
  auto end = std::make_shared<v1::ServerMessage>();
  end->mutable_end();
  EXPECT_TRUE(queue.push(end));
  EXPECT_TRUE(queue.next() == end);
  EXPECT_FALSE(queue.next());
}

TEST(OutgoingMessagesTest, AWrittenFrameSaysHowLongItTookAControlMessageDoesNot) {
  OutgoingMessages queue;
  EXPECT_FALSE(queue.written());
  queue.push(welcome());
  queue.push(frame(1));
  ASSERT_TRUE(queue.next()->has_welcome());
  EXPECT_FALSE(queue.written());
  std::this_thread::sleep_for(std::chrono::milliseconds(5));
  ASSERT_TRUE(queue.next()->has_frame());
  const auto send_ms = queue.written();
  ASSERT_TRUE(send_ms);
  EXPECT_GE(*send_ms, 5.0);  // from its push, waiting behind the welcome included
  EXPECT_FALSE(queue.written());  // once
  // What next() gives is what written() speaks of: a frame taken but not reported written, then
  // a control message written, gives no frame's time.
  queue.push(frame(2));
  ASSERT_TRUE(queue.next()->has_frame());
  queue.push(welcome());
  ASSERT_TRUE(queue.next()->has_welcome());
  EXPECT_FALSE(queue.written());
}

}  // namespace
}  // namespace fluidcast::server

// The hub's snapshot calls (GetSnapshot, PutSnapshot) on this machine's device: each is answered
// once, also when its work fails where wording the failure needs memory there may be none of.
#include "session/session_hub.h"

#include <gtest/gtest.h>

#include <chrono>
#include <condition_variable>
#include <future>
#include <memory>
#include <mutex>
#include <new>
#include <optional>
#include <string>
#include <utility>

#include "gpu_test_support.h"

namespace fluidcast::server {
namespace {

using namespace std::chrono_literals;

class WelcomeSink : public ViewerSink {
 public:
  bool deliver(std::shared_ptr<const v1::ServerMessage> message) override {
    const std::lock_guard lock(mutex_);
    if (message->has_welcome()) welcome_ = message->welcome();
    welcomed_.notify_all();
    return true;
  }
  void end(const Refusal&) override {}
  // It comes after the hub's `done` (at most 20 s).
  v1::Welcome welcome() {
    std::unique_lock lock(mutex_);
    welcomed_.wait_for(lock, 20s, [this] { return welcome_.has_value(); });
    return welcome_.value_or(v1::Welcome());
  }

 private:
  std::mutex mutex_;
  std::condition_variable welcomed_;
  std::optional<v1::Welcome> welcome_;
};

// One answer a call's `done` gave; a second fails the test.
template <typename Result>
class Answer {
 public:
  void give(Result result) {
    const std::lock_guard lock(mutex_);
    EXPECT_FALSE(given_) << "a call was answered twice";
    if (given_) return;
    given_ = true;
    promise_.set_value(std::move(result));
  }
  // The answer, or nothing after 20 s.
  std::optional<Result> within_20s() {
    std::future<Result> future = promise_.get_future();
    if (future.wait_for(20s) != std::future_status::ready) return std::nullopt;
    return future.get();
  }

 private:
  std::mutex mutex_;
  bool given_ = false;
  std::promise<Result> promise_;
};

class SessionHubTest : public testing::GpuTest {
 protected:
  SessionHubTest() : hub_(context(), false, limits(), std::nullopt, metrics_) {}
  ~SessionHubTest() override {
    viewer_.reset();
    hub_.stop();
  }

  static ServerLimits limits() {
    ServerLimits limits;
    limits.max_particles = 1000;
    limits.default_particles = 300;
    limits.max_width = 64;
    limits.max_height = 48;
    return limits;
  }

  // A session of 300 particles; its control key.
  std::string open_session() {
    v1::Hello hello;
    hello.mutable_viewport()->set_width(64);
    hello.mutable_viewport()->set_height(48);
    hello.mutable_create()->set_particles(300);
    auto sink = std::make_shared<WelcomeSink>();
    std::promise<SessionHub::Opened> opened;
    hub_.open(hello, "127.0.0.1", sink,
              [&](SessionHub::Opened result) { opened.set_value(std::move(result)); });
    SessionHub::Opened result = opened.get_future().get();
    EXPECT_FALSE(result.refusal) << result.refusal->what();
    viewer_ = std::move(result.viewer);
    const std::string key = sink->welcome().access().control_key();
    EXPECT_FALSE(key.empty()) << "no Welcome";
    return key;
  }

  // Stands in for an allocation that fails in a call's work, before its answer.
  static bool no_memory() { throw std::bad_alloc(); }

  Metrics metrics_;
  SessionHub hub_;
  std::shared_ptr<ViewerLink> viewer_;
};

TEST_F(SessionHubTest, ASnapshotCallWhoseWorkFindsNoMemoryIsAnsweredOnce) {
  const std::string key = open_session();
  Answer<std::optional<Refusal>> failed;
  hub_.snapshot(
      key,
      [&](std::optional<v1::Snapshot>, std::optional<Refusal> refusal) { failed.give(refusal); },
      no_memory);
  const auto answer = failed.within_20s();
  ASSERT_TRUE(answer) << "the call was never answered";
  ASSERT_TRUE(*answer);
  EXPECT_EQ((*answer)->code(), RefusalCode::resource_exhausted) << (*answer)->what();

  Answer<std::optional<v1::Snapshot>> taken;  // and the next call is served
  hub_.snapshot(key, [&](std::optional<v1::Snapshot> snapshot, std::optional<Refusal>) {
    taken.give(std::move(snapshot));
  });
  const auto snapshot = taken.within_20s();
  ASSERT_TRUE(snapshot && *snapshot);
  EXPECT_EQ((*snapshot)->positions_size(), 3 * 300);
}

TEST_F(SessionHubTest, APutSnapshotCallWhoseWorkFindsNoMemoryIsAnsweredOnce) {
  const std::string key = open_session();
  Answer<std::optional<v1::Snapshot>> taken;
  hub_.snapshot(key, [&](std::optional<v1::Snapshot> snapshot, std::optional<Refusal>) {
    taken.give(std::move(snapshot));
  });
  const auto snapshot = taken.within_20s();
  ASSERT_TRUE(snapshot && *snapshot);

  Answer<std::optional<Refusal>> failed;
  hub_.load(
      key, std::make_shared<const v1::Snapshot>(**snapshot),
      [&](std::uint32_t, std::optional<Refusal> refusal) { failed.give(std::move(refusal)); },
      no_memory);
  const auto answer = failed.within_20s();
  ASSERT_TRUE(answer) << "the call was never answered";
  ASSERT_TRUE(*answer);
  EXPECT_EQ((*answer)->code(), RefusalCode::resource_exhausted) << (*answer)->what();
}

}  // namespace
}  // namespace fluidcast::server

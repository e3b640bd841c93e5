// The snapshot calls' work on the worker: held to its share of the worker's time, each session's
// line in turn, and answered when the worker stops.
#include "session/side_work.h"

#include <gtest/gtest.h>

#include <chrono>
#include <functional>
#include <string>
#include <vector>

namespace fluidcast::server {
namespace {

using std::chrono::milliseconds;

// A worker's clock that moves only as its jobs and ticks say.
struct FakeClock {
  SideWork::Clock::time_point now{};
  std::function<SideWork::Clock::time_point()> reader() {
    return [this] { return now; };
  }
};

TEST(SideWork, JobsTakeAtMostTheirShareOfTheWorkersTime) {
  FakeClock clock;
  SideWork work;
  milliseconds busy{0};
  // Far more than the worker could do: 1000 calls of 20 ms each, in four sessions' lines.
  for (int k = 0; k < 1000; ++k) {
    work.add("session " + std::to_string(k % 4), {[&] {
                                                    clock.now += milliseconds(20);
                                                    busy += milliseconds(20);
                                                  },
                                                  [] {}});
  }
  // Two seconds of ticks, 16 ms of frames each, the side work run between them.
  const auto start = clock.now;
  while (clock.now - start < std::chrono::seconds(2)) {
    work.run_due(clock.reader());
    clock.now += milliseconds(16);
  }
  const double share =
      double(busy.count()) / std::chrono::duration<double, std::milli>(clock.now - start).count();
  EXPECT_LE(share, SideWork::kShare + 0.02);
  EXPECT_GE(share, SideWork::kShare * 0.5) << "the calls must still be answered";
}

TEST(SideWork, EachSessionsLineTakesItsTurn) {
  FakeClock clock;
  SideWork work;
  std::vector<std::string> ran;
  const auto job = [&](std::string name) {
    return SideWork::Job{[&ran, name] { ran.push_back(name); }, [] {}};
  };
  for (int k = 0; k < 5; ++k) work.add("busy", job("busy " + std::to_string(k)));
  work.add("quiet", job("quiet"));
  work.run_due(clock.reader());  // jobs that take no time all run
  ASSERT_EQ(ran.size(), 6u);
  EXPECT_EQ(ran[1], "quiet") << "a session's one call waits behind another's five";
}

TEST(SideWork, AJobAfterALongOneWaits) {
  FakeClock clock;
  SideWork work;
  int runs = 0;
  for (int k = 0; k < 2; ++k) {
    work.add("a", {[&] {
                     ++runs;
                     clock.now += milliseconds(30);
                   },
                   [] {}});
  }
  work.run_due(clock.reader());
  EXPECT_EQ(runs, 1);
  clock.now += milliseconds(80);  // 30 ms of work: the next may start 90 ms after it
  work.run_due(clock.reader());
  EXPECT_EQ(runs, 1);
  clock.now += milliseconds(10);
  work.run_due(clock.reader());
  EXPECT_EQ(runs, 2);
}

TEST(SideWork, WhatWaitsWhenTheWorkerStopsIsRefused) {
  FakeClock clock;
  SideWork work;
  int ran = 0, refused = 0;
  for (int k = 0; k < 3; ++k) {
    work.add("a", {[&] {
                     ++ran;
                     clock.now += milliseconds(10);
                   },
                   [&] { ++refused; }});
  }
  work.run_due(clock.reader());
  work.refuse_all();
  EXPECT_EQ(ran, 1);
  EXPECT_EQ(refused, 2);
  work.run_due(clock.reader());
  EXPECT_EQ(ran + refused, 3) << "a job is answered once";
}

}  // namespace
}  // namespace fluidcast::server

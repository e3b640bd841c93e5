// How sessions share the GPU's time: water-filling, grants, accounts, cost estimates, and the
// simulation speed. Pure arithmetic; no Vulkan.
#include "session/gpu_budget.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numeric>
#include <string>
#include <vector>

#include "session/sim_speed.h"

namespace fluidcast::server {
namespace {

double sum(const std::vector<double>& values) {
  return std::accumulate(values.begin(), values.end(), 0.0);
}

TEST(ShareEquallyTest, SmallDemandsAreMetAndTheRestSplitsWhatIsLeft) {
  const std::vector<double> demands = {1.0, 10.0, 10.0};
  const auto shares = share_equally(9.0, demands);
  EXPECT_DOUBLE_EQ(shares[0], 1.0);
  EXPECT_DOUBLE_EQ(shares[1], 4.0);
  EXPECT_DOUBLE_EQ(shares[2], 4.0);
}

TEST(ShareEquallyTest, NeverMoreThanTheBudgetNorThanAsked) {
  const std::vector<double> demands = {0.0, 3.0, 7.5, 100.0, 2.0};
  for (double budget : {0.0, 1.0, 5.0, 20.0, 1000.0}) {
    const auto shares = share_equally(budget, demands);
    EXPECT_LE(sum(shares), budget + 1e-9);
    for (std::size_t k = 0; k < demands.size(); ++k) EXPECT_LE(shares[k], demands[k] + 1e-12);
    // Everything asked is given when it fits; the whole budget is used when it does not.
    EXPECT_NEAR(sum(shares), std::min(budget, sum(demands)), 1e-9);
  }
}

TEST(ShareEquallyTest, NegativeBudgetsAndDemandsGiveNothing) {
  const std::vector<double> demands = {-1.0, 2.0};
  EXPECT_EQ(share_equally(-5.0, demands), (std::vector<double>{0.0, 0.0}));
  EXPECT_EQ(share_equally(5.0, demands), (std::vector<double>{0.0, 2.0}));
}

TEST(GrantGpuTimeTest, AHeavySessionCannotTakeTheLightOnesShare) {
  // 60 Hz; a 1M-particle session wants 40 ms of substeps and a 7 ms frame, three small ones 1 ms
  // of each.
  const std::vector<GpuDemand> demands = {
      {40.0, 7.0, true}, {1.0, 1.0, true}, {1.0, 1.0, true}, {1.0, 1.0, true}};
  const double period = 1000.0 / 60.0;
  const auto grants = grant_gpu_time(period, 0.5, 0.5, demands);
  for (std::size_t k = 1; k < 4; ++k) {
    EXPECT_DOUBLE_EQ(grants[k].sim_ms, 1.0);
    EXPECT_DOUBLE_EQ(grants[k].render_ms, 1.0);
    EXPECT_TRUE(grants[k].contended());
  }
  // The heavy one simulates with what the half period leaves, and renders with what the other
  // half leaves: short of its 7 ms frame, so its account pays for one every few ticks.
  EXPECT_NEAR(grants[0].sim_ms, 0.5 * period - 3.0, 1e-9);
  EXPECT_NEAR(grants[0].render_ms, 0.5 * period - 3.0, 1e-9);
  double total = 0.0;
  for (const GpuGrant& g : grants) total += g.sim_ms + g.render_ms;
  EXPECT_LE(total, period + 1e-9);
}

TEST(ShareBetweenClientsTest, AClientWithManySessionsDividesItsOwnShare) {
  // One client's three sessions and another's one, all asking for the whole budget.
  const std::vector<double> demands = {30.0, 30.0, 30.0, 30.0};
  const std::vector<std::string> clients = {"10.0.0.7", "10.0.0.7", "10.0.0.7", "10.0.0.9"};
  const auto shares = share_between_clients(30.0, demands, clients);
  EXPECT_DOUBLE_EQ(shares[3], 15.0);
  for (std::size_t k = 0; k < 3; ++k) EXPECT_DOUBLE_EQ(shares[k], 5.0);
  // What a client does not need goes to the others; one client alone is shared per session.
  const std::vector<double> small = {30.0, 30.0, 2.0};
  const std::vector<std::string> two = {"a", "a", "b"};
  EXPECT_EQ(share_between_clients(30.0, small, two), (std::vector<double>{14.0, 14.0, 2.0}));
  const std::vector<std::string> one = {"a", "a", "a"};
  EXPECT_EQ(share_between_clients(30.0, small, one), share_equally(30.0, small));
}

TEST(GrantGpuTimeTest, ManySessionsOfOneClientDoNotCrowdOutAnother) {
  // A client with seven sessions and a bystander with one, each wanting a 10 ms frame a tick.
  std::vector<GpuDemand> demands(8, GpuDemand{0.0, 10.0, true, false, "attacker"});
  demands[7].client = "bystander";
  const auto grants = grant_gpu_time(20.0, 0.5, 0.5, demands);
  EXPECT_DOUBLE_EQ(grants[7].render_ms, 10.0);  // half the device: all it asks
  for (std::size_t k = 0; k < 7; ++k) EXPECT_NEAR(grants[k].render_ms, 10.0 / 7.0, 1e-12);
}

TEST(GrantGpuTimeTest, RenderingGetsWhatSimulationLeaves) {
  const std::vector<GpuDemand> demands = {{0.0, 30.0, true}};
  const auto grants = grant_gpu_time(20.0, 0.5, 0.5, demands);
  EXPECT_DOUBLE_EQ(grants[0].render_ms, 20.0);
  EXPECT_FALSE(grants[0].contended());  // alone: nobody waits behind its frames
}

TEST(GrantGpuTimeTest, AGpuSolverTakesWhatRenderingLeavesUpToTheBusyShare) {
  // A 1M-particle viewer alone: its fluid wants 40 ms a tick, its frame 1 ms.
  const std::vector<GpuDemand> lone = {{40.0, 1.0, true}};
  auto grants = grant_gpu_time(20.0, 0.5, 0.8, lone);
  EXPECT_DOUBLE_EQ(grants[0].sim_ms, 15.0);    // 0.8 of the period, less the frame
  EXPECT_DOUBLE_EQ(grants[0].render_ms, 1.0);  // the frame; 4 ms of headroom stay idle
  // At or below the simulation's share, none beyond it.
  EXPECT_DOUBLE_EQ(grant_gpu_time(20.0, 0.5, 0.5, lone)[0].sim_ms, 10.0);
  EXPECT_DOUBLE_EQ(grant_gpu_time(20.0, 0.5, 0.3, lone)[0].sim_ms, 10.0);
  // Frames due come first: with 3 ms of them, the fluid gets 0.8 · 20 − 3; with 7, its share.
  std::vector<GpuDemand> busy = {{40.0, 1.0, true, true, "a"}, {0.0, 2.0, true, true, "b"}};
  grants = grant_gpu_time(20.0, 0.5, 0.8, busy);
  EXPECT_DOUBLE_EQ(grants[0].sim_ms, 13.0);
  EXPECT_DOUBLE_EQ(grants[1].render_ms, 2.0);
  busy[1].render_ms = 6.0;
  grants = grant_gpu_time(20.0, 0.5, 0.8, busy);
  EXPECT_DOUBLE_EQ(grants[0].sim_ms, 10.0);
  EXPECT_DOUBLE_EQ(grants[1].render_ms, 6.0);
  // Two heavy clients split the spare equally; a CPU solver's steps get none of it.
  const std::vector<GpuDemand> heavy = {
      {40.0, 1.0, true, true, "a"}, {40.0, 1.0, true, true, "b"}, {40.0, 1.0, true, false, "c"}};
  grants = grant_gpu_time(30.0, 0.5, 0.8, heavy);
  EXPECT_DOUBLE_EQ(grants[2].sim_ms, 5.0);  // its third of the simulation's share
  EXPECT_DOUBLE_EQ(grants[0].sim_ms, 5.0 + 0.5 * (24.0 - 10.0 - 3.0));
  EXPECT_DOUBLE_EQ(grants[0].sim_ms, grants[1].sim_ms);
  // What the device does this tick: the GPU solvers' steps and the frames due, 0.8 of it.
  EXPECT_DOUBLE_EQ(grants[0].sim_ms + grants[1].sim_ms + 3.0, 24.0);
}

TEST(GrantGpuTimeTest, ACpuSolversStepsLeaveTheDeviceToRendering) {
  const std::vector<GpuDemand> demands = {{10.0, 20.0, true, false}, {10.0, 20.0, true, false}};
  const auto grants = grant_gpu_time(16.0, 0.5, 0.5, demands);
  EXPECT_DOUBLE_EQ(grants[0].sim_ms, 4.0);
  EXPECT_DOUBLE_EQ(grants[0].render_ms, 8.0);  // half the whole period, not of what is left
}

TEST(GrantGpuTimeTest, OnlyOtherSessionsViewersMakeAContest) {
  // Watched, with no frame due this tick: its next frame would still wait behind a long one.
  const std::vector<GpuDemand> demands = {
      {5.0, 3.0, true, true, "a"}, {5.0, 0.0, true, true, "b"}, {0.0, 0.0, false, true, "c"}};
  const auto grants = grant_gpu_time(16.0, 0.5, 0.5, demands);
  EXPECT_EQ(grants[0].others_watched, 1u);
  EXPECT_EQ(grants[1].others_watched, 1u);
  EXPECT_EQ(grants[2].others_watched, 2u);
  const std::vector<GpuDemand> alone = {{5.0, 3.0, true}, {0.0, 0.0, false}};
  EXPECT_FALSE(grant_gpu_time(16.0, 0.5, 0.5, alone)[0].contended());
}

TEST(GrantGpuTimeTest, ThoseWaitingBehindAFrameAreCountedByClient) {
  // A phone beside a client with seven watched sessions: its long frames hold back one client.
  std::vector<GpuDemand> demands(8, GpuDemand{0.0, 5.0, true, true, "many"});
  demands[7].client = "phone";
  const auto grants = grant_gpu_time(16.0, 0.5, 0.5, demands);
  EXPECT_EQ(grants[7].others_watched, 1u);
  // One of the seven: the phone, and its own client's six other sessions, once.
  EXPECT_EQ(grants[0].others_watched, 2u);
  // A client's only other session watched still waits behind its frames.
  const std::vector<GpuDemand> own = {
      {0.0, 5.0, true, true, "a"}, {0.0, 5.0, true, true, "a"}, {0.0, 0.0, false, true, "b"}};
  const auto own_grants = grant_gpu_time(16.0, 0.5, 0.5, own);
  EXPECT_EQ(own_grants[0].others_watched, 1u);
  EXPECT_EQ(own_grants[2].others_watched, 1u);
}

TEST(GrantGpuTimeTest, AnItemLongerThanATickPaysForTheFramesItHoldsBack) {
  GpuGrant grant;
  grant.period_ms = 10.0;
  EXPECT_DOUBLE_EQ(grant.charge(25.0), 25.0);  // alone: its own time
  grant.others_watched = 3;
  EXPECT_DOUBLE_EQ(grant.charge(8.0), 8.0);  // within a tick: nobody misses a frame
  EXPECT_DOUBLE_EQ(grant.charge(25.0), 25.0 + 3 * 15.0);
}

TEST(FrameChargeTest, AFrameIsSettledAgainstWhatItTook) {
  GpuGrant grant;
  grant.period_ms = 10.0;
  grant.others_watched = 2;
  // Priced at 4 ms, it took 25 (a new renderer drew the whole scene): it owes the rest, and the
  // 15 ms beyond a period that it held two clients' frames back.
  const FrameCharge priced{grant, grant.charge(4.0)};
  EXPECT_DOUBLE_EQ(priced.settle(25.0), 25.0 + 2 * 15.0 - 4.0);
  EXPECT_DOUBLE_EQ(priced.settle(3.0), -1.0);  // overpriced: the difference comes back
  const FrameCharge unpriced{grant, 0.0};      // drawn to be measured
  EXPECT_DOUBLE_EQ(unpriced.settle(6.0), 6.0);
}

TEST(FrameChargeTest, AStallOrAnOddTimestampCostsAtMostASecond) {
  GpuGrant grant;
  grant.period_ms = 10.0;
  const FrameCharge charge{grant, 4.0};
  EXPECT_DOUBLE_EQ(charge.settle(1e12), FrameCharge::kMostMeasuredMs - 4.0);
  // A frame priced beyond the cap is not refunded because of it.
  const FrameCharge dear{grant, 2500.0};
  EXPECT_DOUBLE_EQ(dear.settle(3000.0), 0.0);
  EXPECT_DOUBLE_EQ(dear.settle(2000.0), 0.0);
  EXPECT_DOUBLE_EQ(dear.settle(800.0), -1700.0);  // measured within the cap: the rest comes back
  for (double odd : {0.0, -3.0, std::nan(""), std::numeric_limits<double>::infinity()}) {
    EXPECT_DOUBLE_EQ(charge.settle(odd), 0.0) << odd;  // the price stands
  }
}

TEST(GpuAccountTest, AnItemDearerThanAGrantRunsOnceEnoughTicksPaidForIt) {
  GpuAccount account;
  int runs = 0;
  for (int tick = 0; tick < 40; ++tick) {
    account.deposit(2.0, 10.0);  // 2 ms a tick for an item of 10 ms
    if (account.can_spend()) {
      account.spend(10.0);
      ++runs;
    }
  }
  EXPECT_EQ(runs, 8);  // 80 ms paid over 40 ticks: every fifth tick
}

TEST(GpuAccountTest, CreditCannotBeHoarded) {
  GpuAccount account;
  for (int tick = 0; tick < 100; ++tick) account.deposit(2.0, 3.0);
  EXPECT_DOUBLE_EQ(account.balance_ms(), 5.0);
  EXPECT_EQ(account.affordable(1.0), 5);
  EXPECT_EQ(account.affordable(4.0), 1);
  EXPECT_EQ(account.affordable(1e-300), 1 << 20);  // however cheap, a count that fits
  // An item with no price (0 or NaN) still runs one at a time while the balance is positive, not
  // 1 << 20 of them.
  EXPECT_EQ(account.affordable(0.0), 1);
  EXPECT_EQ(account.affordable(std::nan("")), 1);
  account.spend(6.0);
  EXPECT_EQ(account.affordable(1.0), 0);
}

// A new fluid drops saved credit but keeps a debt: putting a state in must not wipe what a
// session owes (nor what a client carried over from its last one).
TEST(GpuAccountTest, ANewFluidKeepsTheDebtAndDropsTheCredit) {
  GpuAccount account;
  account.deposit(2.0, 3.0);
  account.forget_credit();
  EXPECT_DOUBLE_EQ(account.balance_ms(), 0.0);
  account.spend(7.5);
  account.forget_credit();
  EXPECT_DOUBLE_EQ(account.balance_ms(), -7.5);
}

TEST(CostEstimateTest, FollowsAChangeWithinAFewSamples) {
  CostEstimate cost;
  EXPECT_FALSE(cost.known());
  cost.add(4.0);
  EXPECT_TRUE(cost.known());
  EXPECT_DOUBLE_EQ(cost.ms(), 4.0);
  for (int k = 0; k < 12; ++k) cost.add(1.0);
  EXPECT_NEAR(cost.ms(), 1.0, 0.1);
  cost.add(-3.0);  // not a duration: ignored
  cost.add(std::nan(""));
  cost.add(0.0);  // nothing measured (no timestamps): not free
  EXPECT_NEAR(cost.ms(), 1.0, 0.1);
  cost.add(1000.0);  // one stall
  EXPECT_LT(cost.ms(), 1.5);
  for (int k = 0; k < 12; ++k) cost.add(10.0);  // a real rise, tenfold
  EXPECT_GT(cost.ms(), 8.0);
  CostEstimate unmeasured;
  unmeasured.add(0.0);
  EXPECT_FALSE(unmeasured.known());
}

TEST(CostEstimateTest, AResizedFrameIsPricedAtItsNewSizeAtOnce) {
  CostEstimate cost;
  cost.scale(4.0);  // nothing known: nothing to scale
  EXPECT_FALSE(cost.known());
  cost.add(0.5);
  cost.scale(3600.0);  // 16×16 → 1280×720
  EXPECT_DOUBLE_EQ(cost.ms(), 1800.0);
  cost.scale(0.0);  // not a size change
  cost.scale(std::nan(""));
  EXPECT_DOUBLE_EQ(cost.ms(), 1800.0);
  cost.scale(1.0 / 3600.0);
  EXPECT_DOUBLE_EQ(cost.ms(), 0.5);
}

TEST(ClientDebtsTest, AClientsNextSessionInheritsWhatItsLastOneOwed) {
  ClientDebts debts;
  debts.record("10.0.0.7", 200.0, 1000.0);
  debts.record("10.0.0.9", -5.0, 1000.0);  // in credit: owes nothing
  EXPECT_DOUBLE_EQ(debts.take("10.0.0.9", 1000.0, 0.5), 0.0);
  // 100 ms later, with half of the account's time its share: half of that is forgiven.
  EXPECT_DOUBLE_EQ(debts.take("10.0.0.7", 1100.0, 0.5), 150.0);
  EXPECT_DOUBLE_EQ(debts.take("10.0.0.7", 1100.0, 0.5), 0.0);  // taken once
  // Two sessions ending in debt add up; a long enough wait forgives it all.
  debts.record("a", 50.0, 0.0);
  debts.record("a", 50.0, 10.0);
  EXPECT_DOUBLE_EQ(debts.take("a", 10.0, 1.0), 90.0);
  debts.record("b", 50.0, 0.0);
  EXPECT_DOUBLE_EQ(debts.take("b", 1000.0, 1.0 / 3.0), 0.0);
  // A quarter share forgives a quarter of the 60 ms waited: 15 of the 50 owed.
  debts.record("c", 50.0, 0.0);
  EXPECT_DOUBLE_EQ(debts.take("c", 60.0, 0.25), 35.0);
}

TEST(ClientDebtsTest, ManyAddressesKeepItsMemoryBounded) {
  ClientDebts debts;
  for (std::size_t k = 0; k <= ClientDebts::kMostClients; ++k) {
    debts.record("client " + std::to_string(k), 10.0, double(k));
  }
  EXPECT_DOUBLE_EQ(debts.take("client 0", 0.0, 1.0), 0.0);  // the oldest, forgotten
  EXPECT_DOUBLE_EQ(debts.take("client 1", 1.0, 1.0), 10.0);
}

TEST(SimSpeedTest, SimulatedSecondsPerWallSecondOverTheLastSecond) {
  SimSpeed speed;
  const SimSpeed::Clock::time_point start{};
  EXPECT_EQ(speed.speed(), 0.0);
  // Real time for two seconds, then half speed.
  for (int tick = 0; tick <= 120; ++tick) {
    speed.record(start + std::chrono::milliseconds(tick * 1000 / 60), tick / 60.0, true);
  }
  EXPECT_NEAR(speed.speed(), 1.0, 1e-6);
  double sim = 2.0;
  for (int tick = 121; tick <= 240; ++tick) {
    sim += 0.5 / 60.0;
    speed.record(start + std::chrono::milliseconds(tick * 1000 / 60), sim, true);
  }
  EXPECT_NEAR(speed.speed(), 0.5, 0.02);
}

TEST(SimSpeedTest, APauseOrAClockThatWentBackStartsAfresh) {
  SimSpeed speed;
  const SimSpeed::Clock::time_point start{};
  speed.record(start, 5.0, true);
  speed.record(start + std::chrono::milliseconds(100), 5.1, true);
  EXPECT_NEAR(speed.speed(), 1.0, 1e-6);
  speed.record(start + std::chrono::milliseconds(200), 5.1, false);
  EXPECT_EQ(speed.speed(), 0.0);
  speed.record(start + std::chrono::milliseconds(300), 5.1, true);
  speed.record(start + std::chrono::milliseconds(400), 0.0, true);  // reset
  EXPECT_EQ(speed.speed(), 0.0);
}

}  // namespace
}  // namespace fluidcast::server

// Which due frames a session draws in a tick: all while nobody else is watched; otherwise those
// its account pays for, a frame not yet priced, the once-a-second floor while the debt is small,
// and one frame now and then for the longest-waiting viewer however deep the debt.
#include "session/frame_admission.h"

#include <gtest/gtest.h>

#include <vector>

namespace fluidcast::server {
namespace {

// Another client is watched: frames beyond the grant wait.
GpuGrant contended(std::size_t others = 1) {
  GpuGrant grant;
  grant.period_ms = 10.0;
  grant.others_watched = others;
  return grant;
}

GpuAccount with_balance(double ms) {
  GpuAccount account;
  account.spend(-ms);
  return account;
}

std::vector<bool> drawn(const FrameAdmission& admission) {
  std::vector<bool> result;
  for (const auto& frame : admission.frames) result.push_back(frame.drawn);
  return result;
}

constexpr double kLongAgoMs = 1e9;

TEST(AdmitFramesTest, WithNobodyElseWatchedEveryDueFrameIsDrawnUncharged) {
  GpuAccount account = with_balance(-1e6);
  const std::vector<DueFrame> due = {{20.0, 0.0}, {std::nullopt, 0.0}};
  const FrameAdmission admission = admit_frames(GpuGrant{}, account, due, kLongAgoMs);
  EXPECT_EQ(drawn(admission), (std::vector<bool>{true, true}));
  EXPECT_FALSE(admission.frames[0].charge);
  EXPECT_FALSE(admission.frames[1].charge);
  EXPECT_DOUBLE_EQ(account.balance_ms(), -1e6);
  EXPECT_FALSE(admission.drew_in_debt);
}

TEST(AdmitFramesTest, CreditPaysForFramesUntilItIsSpentThenTheyWait) {
  GpuAccount account = with_balance(5.0);
  const std::vector<DueFrame> due = {{4.0, 0.0}, {4.0, 0.0}, {4.0, 0.0}};
  const FrameAdmission admission = admit_frames(contended(), account, due, kLongAgoMs);
  // The second starts on the last millisecond of credit and takes the balance below zero.
  EXPECT_EQ(drawn(admission), (std::vector<bool>{true, true, false}));
  EXPECT_DOUBLE_EQ(admission.frames[0].charge->charged_ms, 4.0);
  EXPECT_DOUBLE_EQ(account.balance_ms(), -3.0);
  EXPECT_FALSE(admission.frames[0].on_floor);
  EXPECT_FALSE(admission.frames[1].on_floor);
}

TEST(AdmitFramesTest, AFrameLongerThanATickIsChargedTheTimeItHoldsOthersBack) {
  GpuAccount account = with_balance(1.0);
  const std::vector<DueFrame> due = {{30.0, 0.0}};
  const GpuGrant grant = contended(2);
  const FrameAdmission admission = admit_frames(grant, account, due, kLongAgoMs);
  ASSERT_TRUE(admission.frames[0].drawn);
  EXPECT_DOUBLE_EQ(admission.frames[0].charge->charged_ms, grant.charge(30.0));
  EXPECT_DOUBLE_EQ(account.balance_ms(), 1.0 - grant.charge(30.0));
}

TEST(AdmitFramesTest, AFrameNotYetPricedIsDrawnInDebtToBeMeasured) {
  GpuAccount account = with_balance(-500.0);
  const std::vector<DueFrame> due = {{std::nullopt, 0.0}};
  const FrameAdmission admission = admit_frames(contended(), account, due, kLongAgoMs);
  ASSERT_TRUE(admission.frames[0].drawn);
  ASSERT_TRUE(admission.frames[0].charge);
  EXPECT_DOUBLE_EQ(admission.frames[0].charge->charged_ms, 0.0);  // settled once measured
  EXPECT_DOUBLE_EQ(account.balance_ms(), -500.0);
}

TEST(AdmitFramesTest, AViewerWaitingASecondGetsAFrameWhileTheDebtIsSmall) {
  // One other client: the floor holds while the session owes less than half a second.
  const std::vector<DueFrame> due = {{10.0, 999.0}, {10.0, kLongestFrameWaitMs}};
  GpuAccount small_debt = with_balance(-400.0);
  const FrameAdmission floor = admit_frames(contended(1), small_debt, due, 0.0);
  EXPECT_EQ(drawn(floor), (std::vector<bool>{false, true}));
  EXPECT_TRUE(floor.frames[1].on_floor);
  GpuAccount large_debt = with_balance(-600.0);
  EXPECT_EQ(drawn(admit_frames(contended(1), large_debt, due, 0.0)),
            (std::vector<bool>{false, false}));
  // With three other clients it holds only within a quarter of a second.
  GpuAccount same_debt = with_balance(-400.0);
  EXPECT_EQ(drawn(admit_frames(contended(3), same_debt, due, 0.0)),
            (std::vector<bool>{false, false}));
}

TEST(AdmitFramesTest, HoweverDeepTheDebtTheLongestWaitingViewerGetsAFrameEveryFiveSeconds) {
  const std::vector<DueFrame> due = {
      {10.0, 6000.0}, {10.0, 7000.0}, {std::nullopt, 0.0}, {10.0, 5500.0}};
  GpuAccount account = with_balance(-1e5);
  const FrameAdmission admission = admit_frames(contended(), account, due, kLongAgoMs);
  EXPECT_EQ(drawn(admission), (std::vector<bool>{false, true, true, false}));
  EXPECT_TRUE(admission.drew_in_debt);
  EXPECT_TRUE(admission.frames[1].on_floor);
  EXPECT_FALSE(admission.frames[2].on_floor);  // unpriced: drawn to be measured
  EXPECT_DOUBLE_EQ(account.balance_ms(), -1e5 - 10.0);

  // Not again until five seconds after the last such frame.
  GpuAccount again = with_balance(-1e5);
  const FrameAdmission soon = admit_frames(contended(), again, due, 4999.0);
  EXPECT_EQ(drawn(soon), (std::vector<bool>{false, false, true, false}));
  EXPECT_FALSE(soon.drew_in_debt);
  // Nor for a viewer that has not waited that long itself.
  GpuAccount fresh = with_balance(-1e5);
  const std::vector<DueFrame> recent = {{10.0, 4000.0}};
  EXPECT_EQ(drawn(admit_frames(contended(), fresh, recent, kLongAgoMs)),
            (std::vector<bool>{false}));
}

TEST(AdmitFramesTest, AFrameDearerThanAnEqualShareOfFiveSecondsWaitsAsLongAsTheShareTakesToPay) {
  // 4 s a frame against one other client: an equal share pays for it every 8 s.
  GpuGrant grant = contended(1);
  grant.period_ms = 1e6;  // no hold-back charge: the price alone
  const std::vector<DueFrame> waited_7 = {{4000.0, 7000.0}};
  GpuAccount account = with_balance(-1e5);
  EXPECT_FALSE(admit_frames(grant, account, waited_7, kLongAgoMs).frames[0].drawn);
  const std::vector<DueFrame> waited_8 = {{4000.0, 8000.0}};
  EXPECT_TRUE(admit_frames(grant, account, waited_8, kLongAgoMs).frames[0].drawn);
}

TEST(AdmitFramesTest, AFrameTheCreditPaysForDoesNotRestartTheWaitInDebt) {
  // The longest-waiting viewer is drawn on credit: the next frame whatever the debt is not put
  // off by it.
  GpuAccount account = with_balance(50.0);
  const std::vector<DueFrame> due = {{10.0, 9000.0}};
  const FrameAdmission admission = admit_frames(contended(), account, due, kLongAgoMs);
  EXPECT_TRUE(admission.frames[0].drawn);
  EXPECT_FALSE(admission.drew_in_debt);
}

TEST(AdmitFramesTest, AFrameTheOneSecondFloorPaysForDoesNotRestartTheWaitInDebt) {
  // In debt, but within the floor's bound: the longest-waiting viewer is drawn by the floor.
  GpuAccount account = with_balance(-100.0);
  const std::vector<DueFrame> due = {{10.0, 9000.0}};
  const FrameAdmission admission = admit_frames(contended(), account, due, kLongAgoMs);
  EXPECT_TRUE(admission.frames[0].drawn);
  EXPECT_FALSE(admission.drew_in_debt);
}

TEST(AdmitFramesTest, WhenCreditRunsOutWithinATickTheLongestWaitingStillGetsItsFrame) {
  // The first frame spends the credit and sinks the account past the floor's bound; the second,
  // waiting longest, is drawn in debt; the third waits.
  GpuAccount account = with_balance(1.0);
  const std::vector<DueFrame> due = {{900.0, 0.0}, {10.0, 6000.0}, {10.0, 5500.0}};
  GpuGrant grant = contended();
  grant.period_ms = 1e6;  // no hold-back charge
  const FrameAdmission admission = admit_frames(grant, account, due, kLongAgoMs);
  EXPECT_EQ(drawn(admission), (std::vector<bool>{true, true, false}));
  EXPECT_TRUE(admission.drew_in_debt);
}

TEST(AdmitFramesTest, AFrameNotYetPricedIsNeverTheOneDrawnInDebt) {
  // It waited longest, but it is drawn anyway (to be measured); the debt floor goes to the
  // priced frame that waited longest.
  GpuAccount account = with_balance(-1e5);
  const std::vector<DueFrame> due = {{std::nullopt, 60000.0}, {10.0, 6000.0}};
  const FrameAdmission admission = admit_frames(contended(), account, due, kLongAgoMs);
  EXPECT_EQ(drawn(admission), (std::vector<bool>{true, true}));
  EXPECT_TRUE(admission.drew_in_debt);
  EXPECT_DOUBLE_EQ(account.balance_ms(), -1e5 - 10.0);
}

}  // namespace
}  // namespace fluidcast::server

#include "frame_admission.h"

#include <algorithm>

namespace fluidcast::server {
namespace {

// The priced frame that has waited longest, where it may be drawn whatever the debt; none
// otherwise.
std::optional<std::size_t> longest_waiting_in_debt(const GpuGrant& grant,
                                                   std::span<const DueFrame> due,
                                                   double since_drawn_in_debt_ms) {
  std::optional<std::size_t> longest;
  double dearest_ms = 0.0;
  for (std::size_t k = 0; k < due.size(); ++k) {
    if (!due[k].price_ms) continue;
    dearest_ms = std::max(dearest_ms, *due[k].price_ms);
    if (!longest || due[k].waited_ms > due[*longest].waited_ms) longest = k;
  }
  const double wait_ms =
      std::max(kLongestFrameWaitInDebtMs, dearest_ms * double(1 + grant.others_watched));
  if (!longest || due[*longest].waited_ms < wait_ms || since_drawn_in_debt_ms < wait_ms) {
    return std::nullopt;
  }
  return longest;
}

}  // namespace

FrameAdmission admit_frames(const GpuGrant& grant, GpuAccount& account,
                            std::span<const DueFrame> due, double since_drawn_in_debt_ms) {
  FrameAdmission admission;
  admission.frames.resize(due.size());
  if (!grant.contended()) {  // nobody waits behind them
    for (FrameAdmission::Frame& frame : admission.frames) frame.drawn = true;
    return admission;
  }
  const double floor_debt_ms = kLongestFrameWaitMs / double(1 + grant.others_watched);
  const std::optional<std::size_t> longest_waiting =
      longest_waiting_in_debt(grant, due, since_drawn_in_debt_ms);
  for (std::size_t k = 0; k < due.size(); ++k) {
    FrameAdmission::Frame& frame = admission.frames[k];
    if (!due[k].price_ms) {
      frame = {true, FrameCharge{grant, 0.0}};  // settled once measured
      continue;
    }
    const bool paid = account.can_spend();
    const bool on_floor =
        due[k].waited_ms >= kLongestFrameWaitMs && account.balance_ms() > -floor_debt_ms;
    const bool in_debt = k == longest_waiting && !paid && !on_floor;
    if (!paid && !on_floor && !in_debt) continue;  // its share is spent; others go first
    frame = {true, FrameCharge{grant, grant.charge(*due[k].price_ms)}, !paid};
    account.spend(frame.charge->charged_ms);
    admission.drew_in_debt = admission.drew_in_debt || in_debt;
  }
  return admission;
}

}  // namespace fluidcast::server

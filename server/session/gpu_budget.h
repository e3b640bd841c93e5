// How the sessions of one server share the GPU's time, tick by tick (docs/frame-loop.md).
// Pure arithmetic on milliseconds measured with GPU timestamps: no Vulkan, no clocks.
//
// Each tick of period T, the hub asks every session what it would spend (its due frames at their
// measured cost, the substeps real time owes at their measured cost), grants simulation up to
// sim_share·T in all and rendering the rest of T, both shared out by equal GPU time per session,
// and each session spends its grant through accounts that carry credit from tick to tick: a
// frame or a substep dearer than one tick's share runs once enough ticks have paid for it.
#pragma once

#include <span>
#include <vector>

namespace fluidcast::server {

// Equal shares by water-filling: every demand below the common level is met in full, the rest
// get that level, and the level is as high as `budget` allows (the sum never exceeds it). A
// session that needs little leaves its share to the others.
std::vector<double> share_equally(double budget, std::span<const double> demands);

// What one session asks of a tick, in GPU milliseconds.
struct GpuDemand {
  double sim_ms = 0.0;     // the substeps that real time owes
  double render_ms = 0.0;  // the frames that are due
};

// What the hub grants it.
struct GpuGrant {
  double sim_ms = 0.0;
  double render_ms = 0.0;
  // Another session has frames due this tick: frames beyond this one's grant wait. Alone, a
  // session renders every due frame (nobody waits behind it).
  bool contended = false;
};

// The rule, for all sessions at once: simulation shares sim_share·period, rendering the rest of
// the period (what simulation leaves included).
std::vector<GpuGrant> grant_gpu_time(double period_ms, double sim_share,
                                     std::span<const GpuDemand> demands);

// Credit in GPU milliseconds. A tick's grant adds to it; an item (a frame, a substep) may be
// started while the balance is positive and may take it below zero, which later grants repay.
// Credit never exceeds one grant plus the dearest item, so an idle session cannot save up a
// burst. (Frames drawn while no other session has frames due are not charged: nobody waits.)
class GpuAccount {
 public:
  void deposit(double grant_ms, double dearest_item_ms);
  bool can_spend() const { return balance_ms_ > 0.0; }
  void spend(double ms) { balance_ms_ -= ms; }
  double balance_ms() const { return balance_ms_; }
  // How many items of `item_ms` to start now: those the balance covers, and at least one while
  // it is positive.
  int affordable(double item_ms) const;

 private:
  double balance_ms_ = 0.0;
};

// A cost that is measured now and then and drifts (a substep's, a frame's): an exponential
// average that follows a change within a few samples.
class CostEstimate {
 public:
  void add(double ms);
  bool known() const { return known_; }
  double ms() const { return ms_; }

 private:
  double ms_ = 0.0;
  bool known_ = false;
};

}  // namespace fluidcast::server

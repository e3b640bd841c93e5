// How the sessions of one server share the GPU's time, tick by tick (docs/frame-loop.md).
// Pure arithmetic on milliseconds measured with GPU timestamps: no Vulkan, no clocks.
//
// Each tick of period T, the hub asks every session what it would spend (its due frames at their
// measured cost, the substeps real time owes at their measured cost), grants simulation up to
// sim_share·T in all (more, up to busy_share·T with rendering, where rendering leaves it) and
// rendering the rest of T, both shared out by equal GPU time per client and
// then per session of that client,
// and each session spends its grant through accounts that carry credit from tick to tick: a
// frame or a substep dearer than one tick's share runs once enough ticks have paid for it.
#pragma once

#include <algorithm>
#include <cstddef>
#include <map>
#include <span>
#include <string>
#include <vector>

namespace fluidcast::server {

// Equal shares by water-filling: every demand below the common level is met in full, the rest
// get that level, and the level is as high as `budget` allows (the sum never exceeds it). A
// session that needs little leaves its share to the others.
std::vector<double> share_equally(double budget, std::span<const double> demands);

// Equal shares between clients first, then between each client's demands: a client that opens
// more sessions divides its own share, not everyone's. `clients[k]` names demand k's client.
std::vector<double> share_between_clients(double budget, std::span<const double> demands,
                                          std::span<const std::string> clients);

// What one session asks of a tick, in GPU milliseconds.
struct GpuDemand {
  double sim_ms = 0.0;     // the substeps that real time owes
  double render_ms = 0.0;  // the frames that are due
  bool watched = false;    // it has viewers, whose frames anything long holds back
  // Its solver runs on the GPU. A CPU solver's substeps take the worker thread's time, not the
  // device's: they count against the simulation share, not against rendering.
  bool sim_on_gpu = true;
  // Who created the session (its address): sessions of one client share one client's time.
  std::string client;
};

// What the hub grants it.
struct GpuGrant {
  double sim_ms = 0.0;
  double render_ms = 0.0;
  double period_ms = 0.0;  // of a tick
  // Who waits behind its frames: each other client with a session watched, and its own client
  // once more if another of its sessions is watched (counted by clients, not sessions, so that
  // opening many sessions does not make everyone else's long frames dearer). With nobody, a
  // session renders every due frame; with somebody, frames beyond its grant wait: even when their
  // frames are not due in this tick, a long frame now holds back theirs in the next.
  std::size_t others_watched = 0;
  bool contended() const { return others_watched > 0; }
  // What an item (a substep, a frame) of `item_ms` costs the session's account: its own time,
  // plus, where it is longer than a tick, the time it holds the other sessions' frames back (the
  // GPU runs one thing at a time). A substep or frame that blocks the device for several periods
  // therefore runs that much less often, and the sessions beside it keep their frame rate.
  double charge(double item_ms) const;
};

// What a frame was charged when it was submitted, under which grant; settled once its GPU time is
// measured (a price is an estimate: a renderer's first frame draws the whole scene, and a frame
// drawn to be measured had no price at all).
struct FrameCharge {
  // A frame is settled as if it took at most this long (its price stands where that was higher):
  // a stall or a driver's odd timestamp must not cost a session minutes of frames.
  static constexpr double kMostMeasuredMs = 1000.0;

  GpuGrant grant;
  double charged_ms = 0.0;
  // What is still owed once the frame took `measured_ms` (negative: a refund); nothing where
  // the measurement is not a positive, finite duration.
  double settle(double measured_ms) const;
};

// The rule, for all sessions at once: simulation shares sim_share·period; where GPU solvers want
// more, what rendering does not ask for up to busy_share·period in all is shared out among their
// unmet demands too; rendering gets the rest of the period (what simulation on the GPU leaves
// included). Each is shared between clients and then between a client's sessions. A tick that
// comes late grants no more:
// when the device cannot keep the tick rate, frame rates and fluids slow down alike, and an item
// that overran its tick does not pay for itself.
std::vector<GpuGrant> grant_gpu_time(double period_ms, double sim_share, double busy_share,
                                     std::span<const GpuDemand> demands);

// Credit in GPU milliseconds. A tick's grant adds to it; an item (a frame, a substep) may be
// started while the balance is positive and may take it below zero, which later grants repay.
// Credit never exceeds one grant plus the dearest item, so an idle session cannot save up a
// burst. (Frames drawn while no other session is watched are not charged: nobody waits.)
class GpuAccount {
 public:
  void deposit(double grant_ms, double dearest_item_ms);
  bool can_spend() const { return balance_ms_ > 0.0; }
  void spend(double ms) { balance_ms_ -= ms; }
  // A new fluid (a rebuild, a state put in) costs afresh: credit saved against the old one goes,
  // what the session owes stays (else putting states in would wipe a debt).
  void forget_credit() { balance_ms_ = std::min(balance_ms_, 0.0); }
  double balance_ms() const { return balance_ms_; }
  // How many items of `item_ms` to start now: those the balance covers, and at least one while
  // it is positive.
  int affordable(double item_ms) const;

 private:
  double balance_ms_ = 0.0;
};

// GPU time clients still owe after their sessions ended in debt (an account below zero). Without
// it a client could open a session, spend far beyond its share on a few dear frames (a resize to
// the largest size), leave, and start the next session free of debt, again and again. A debt is
// forgiven as the client sits its share out: wall time times its share of the device's time for
// that account. Pure: times are given in milliseconds.
class ClientDebts {
 public:
  // Beyond this many clients in debt, the oldest debt is forgotten (memory stays bounded
  // whatever the number of addresses).
  static constexpr std::size_t kMostClients = 4096;

  void record(const std::string& client, double owed_ms, double now_ms);
  // What `client` owes at `now_ms`, `share` being the fraction of wall time that repays it (its
  // share of the account's time: sim_share over the clients, say); forgotten here: its new
  // session starts its account that far below zero.
  double take(const std::string& client, double now_ms, double share);

 private:
  struct Debt {
    double owed_ms;
    double since_ms;
  };
  static double left(const Debt& debt, double now_ms, double share);
  std::map<std::string, Debt> debts_;
};

// A cost that is measured now and then and drifts (a substep's, a frame's): an exponential
// average that follows a fall within a few samples and a tenfold rise within a dozen; a sample
// above the estimate counts as at most twice it, so one stall does not dominate. Samples that are
// not a positive, finite duration are ignored: until a real one arrives the cost stays unknown.
class CostEstimate {
 public:
  void add(double ms);
  // The work changed size by `factor` (a frame's pixels, on a resize): the estimate follows at
  // once. Left to samples, whose rises count twice the estimate at most, a frame 3600 times
  // larger would be underpriced for a dozen frames, each holding every other session back.
  void scale(double factor);
  bool known() const { return known_; }
  double ms() const { return ms_; }

 private:
  double ms_ = 0.0;
  bool known_ = false;
};

}  // namespace fluidcast::server

// Which of a session's due frames it draws this tick, and what each is charged
// (docs/frame-loop.md, "Fair sharing"). Pure: times are given in milliseconds.
#pragma once

#include <optional>
#include <span>
#include <vector>

#include "gpu_budget.h"

namespace fluidcast::server {

// A viewer gets a frame at least this often while its session's rendering account owes no more
// than this long of an equal share of the device: a frame rate floor (and fresh measurements for
// a cost that was overestimated) that a session whose frames cost more than its share cannot
// live on.
inline constexpr double kLongestFrameWaitMs = 1000.0;
// However deep its debt, a session draws one frame this often (or, for a frame dearer than an
// equal share of this long, as often as an equal share pays for it), for the viewer that has
// waited longest (since it joined, before its first): a picture that moves now and then.
inline constexpr double kLongestFrameWaitInDebtMs = 5000.0;

// A viewer's frame that is due, as the rule sees it.
struct DueFrame {
  std::optional<double> price_ms;  // none before anything priced it: drawn to be measured
  double waited_ms = 0.0;          // since the viewer's last frame, or since it joined
};

struct FrameAdmission {
  struct Frame {
    bool drawn = false;
    // What a drawn frame is charged; none when nobody waits behind it (it is not charged).
    std::optional<FrameCharge> charge;
    bool on_floor = false;  // drawn though the account could not pay: by a floor
  };
  std::vector<Frame> frames;  // one for each due frame, in order
  // A frame was drawn only because the session had waited kLongestFrameWaitInDebtMs (or its
  // dearer equivalent) in debt: the wait for the next such frame starts again.
  bool drew_in_debt = false;
};

// Draws every due frame while no other session is watched; otherwise those that `account`
// (already credited with this tick's grant) pays for, those under the floors, and a frame not
// yet priced; and spends `account` on them. `since_drawn_in_debt_ms`: since the session last drew
// a frame whatever its debt.
FrameAdmission admit_frames(const GpuGrant& grant, GpuAccount& account,
                            std::span<const DueFrame> due, double since_drawn_in_debt_ms);

}  // namespace fluidcast::server

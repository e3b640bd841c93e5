// How many particles a new session gets when its client does not say: the most that this
// server's solver keeps in real time within ServerLimits::sim_share of the device, measured at
// start on the device itself (a CPU, lavapipe or a GPU of any size get a count that fits them).
// Not busy_share: what that adds is what other sessions' frames leave, gone when they come.
#pragma once

#include <array>
#include <cstdint>
#include <functional>

namespace fluidcast::gpu {
class Context;
}

namespace fluidcast::server {

// The counts tried, smallest first: each probe costs a few steps at that count.
inline constexpr std::array<std::uint32_t, 11> kDefaultParticleLadder{
    1000, 2000, 5000, 10000, 20000, 50000, 100000, 200000, 500000, 1000000, 2000000};
// A fluid in motion takes about two substeps a step of 1/120 s (a dam break: 1.8 at 5000
// particles, 2.2 at 10 000, bench/results/cpu-2026-11-22.md); a probe from rest takes one.
inline constexpr double kSubstepsPerStepInMotion = 2.0;

struct DefaultSize {
  std::uint32_t particles = 0;
  double ms_per_substep = 0;  // at that count, measured
  double device_share = 0;    // of the device's time that count takes in real time
};

// Climbs the ladder while a count, in real time at `steps_per_second`, takes at most `share` of
// the device and stays within `most`; `ms_per_substep(n)` measures one count. The smallest count
// when none fits (the fluid then runs in slow motion, as it would at any count).
DefaultSize choose_default_particles(const std::function<double(std::uint32_t)>& ms_per_substep,
                                     std::uint32_t most, double steps_per_second, double share);

// The cost of one substep of a PBF dam break of `particles` on the solver that sessions use: GPU
// time from timestamps for the GPU solver (wall time where the device has none), wall time for
// the CPU solver on every core.
double measure_ms_per_substep(gpu::Context& context, bool gpu_solver, std::uint32_t particles);

}  // namespace fluidcast::server

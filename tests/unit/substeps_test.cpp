// PBF's substep rule (substeps.h): the travel bound, the walls' bound, the density bound and how it
// follows the measured compression (with a margin when lengthening), where it starts for a fluid
// just loaded, how far it trusts figures of steps still running, and the speed limit that holds the
// travel bound for a particle flung faster than planned; and which of them may stiffen a step.
#include "substeps.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace fluidcast::sim {
namespace {

constexpr float kH = 0.04f;
constexpr float kStep = 1.0f / 120.0f;

PbfSubsteps rule(float travel = 1.0f, float tolerance = 0.01f) {
  SolverParams params;
  params.pbf_travel = travel;
  params.pbf_density_tolerance = tolerance;
  return PbfSubsteps(params, kH);
}

TEST(PbfSubsteps, NothingTravelsMoreThanItsShareOfTheKernelRadius) {
  const PbfSubsteps substeps = rule(0.5f);
  EXPECT_EQ(substeps.count(kStep, 0.0f, 0.0f, 0.0f, 0.0f), 1);
  // 4.7 m/s over 1/120 s is 0.98 h: two substeps of at most half h each.
  EXPECT_EQ(substeps.count(kStep, 4.7f, 0.0f, 0.0f, 0.0f), 2);
  // Gravity's gain over the step counts: 4.7 + 30/120 m/s needs a third.
  EXPECT_EQ(substeps.count(kStep, 4.7f, 0.0f, 0.0f, 30.0f), 3);
  // A collider faster than the fluid sets the pace: 47 m/s, 9.8 h.
  EXPECT_EQ(substeps.count(kStep, 1.0f, 47.0f, 0.0f, 0.0f), 20);
  EXPECT_FLOAT_EQ(substeps.speed_limit(kStep / 2), 0.5f * kH / (kStep / 2));
}

TEST(PbfSubsteps, NothingClosesOnAWallByMoreThanItsShareOfTheSpacing) {
  // h = 0.04 m at the default kernel ratio 2: d = 0.02 m, 0.75 d = 0.015 m.
  const PbfSubsteps substeps = rule(1.0f);
  // 4 m/s over 1/120 s is 0.83 h: one substep by the travel bound, but 2.2 × 0.75 d toward a wall.
  EXPECT_EQ(substeps.count(kStep, 4.0f, 0.0f, 0.0f, 0.0f), 1);
  EXPECT_EQ(substeps.count(kStep, 4.0f, 0.0f, 4.0f, 0.0f), 3);
  // Gravity's gain counts for a particle closing on a wall (5.3 m/s: 2.94; 5.55: 3.08), and for
  // none when none does.
  EXPECT_EQ(substeps.count(kStep, 5.3f, 0.0f, 5.3f, 0.0f), 3);
  EXPECT_EQ(substeps.count(kStep, 5.3f, 0.0f, 5.3f, 30.0f), 4);
  EXPECT_EQ(substeps.count(kStep, 0.0f, 0.0f, 0.0f, 30.0f), 1);
  // pbf_travel scales it as it scales the travel bound.
  EXPECT_EQ(rule(0.5f).count(kStep, 4.0f, 0.0f, 4.0f, 0.0f), 5);
}

TEST(PbfSubsteps, OnlyParticlesThatWouldReachAWallWithinTheReachCloseOnIt) {
  const Box inner{{0.0f, 0.0f, 0.0f}, {1.0f, 1.0f, 1.0f}};
  const float reach = 0.01f;  // s
  // 2 m/s down covers 2 cm in the reach: from 1 cm above the floor it gets there, from 3 cm not.
  EXPECT_EQ(wall_approach({0.5f, 0.01f, 0.5f}, {0.0f, -2.0f, 0.0f}, inner, reach), 2.0f);
  EXPECT_EQ(wall_approach({0.5f, 0.03f, 0.5f}, {0.0f, -2.0f, 0.0f}, inner, reach), 0.0f);
  EXPECT_EQ(wall_approach({0.5f, 0.01f, 0.5f}, {0.0f, 2.0f, 0.0f}, inner, reach), 0.0f);
  // Every wall, the far ones too; the fastest approach of a particle in a corner.
  EXPECT_EQ(wall_approach({0.995f, 0.5f, 0.005f}, {1.0f, 0.0f, -3.0f}, inner, reach), 3.0f);
  EXPECT_EQ(wall_approach({0.5f, 0.99f, 0.5f}, {0.0f, 1.5f, 0.0f}, inner, reach), 1.5f);
  const std::vector<glm::vec3> positions = {{0.5f, 0.01f, 0.5f}, {0.5f, 0.5f, 0.5f}};
  const std::vector<glm::vec3> velocities = {{0.0f, -2.0f, 0.0f}, {0.0f, -9.0f, 0.0f}};
  EXPECT_EQ(largest_wall_approach(positions, velocities, inner, reach), 2.0f);
  EXPECT_EQ(largest_wall_approach(positions, velocities, inner, 0.1f), 9.0f);
}

TEST(PbfSubsteps, TooMuchCompressionShortensTheNextSubstepsAtOnce) {
  PbfSubsteps substeps = rule(1.0f, 0.01f);
  EXPECT_TRUE(std::isinf(substeps.longest_substep()));
  // Four times the tolerance at a whole step: the error goes as Δt², so half the step.
  substeps.observe(kStep, 0.04f);
  EXPECT_FLOAT_EQ(substeps.longest_substep(), kStep / 2);
  EXPECT_EQ(substeps.count(kStep, 0.0f, 0.0f, 0.0f, 9.81f), 2);
}

TEST(PbfSubsteps, LittleCompressionLengthensThemByATenthAStepAtMost) {
  PbfSubsteps substeps = rule(1.0f, 0.01f);
  substeps.observe(kStep, 0.04f);
  // A late report of a small error (a GPU step that was in flight) does not undo it at once.
  substeps.observe(kStep, 0.0f);
  EXPECT_FLOAT_EQ(substeps.longest_substep(), 1.1f * kStep / 2);
  for (int k = 0; k < PbfSubsteps::kRecentSteps + 20; ++k) substeps.observe(kStep / 2, 0.0f);
  EXPECT_EQ(substeps.count(kStep, 0.0f, 0.0f, 0.0f, 9.81f), 1);
}

// A step caught compressed holds the bound for kRecentSteps steps, however little the steps after
// it show (a deep fluid bouncing shows least at the top of its bounce); then it lengthens again.
TEST(PbfSubsteps, ACompressedStepHoldsTheBoundForTheRecentSteps) {
  PbfSubsteps substeps = rule(1.0f, 0.01f);
  substeps.observe(kStep / 2, 0.016f);  // at the tolerance 0.395 of a step: 3 substeps
  ASSERT_EQ(substeps.count(kStep, 0.0f, 0.0f, 0.0f, 9.81f), 3);
  for (int k = 1; k < PbfSubsteps::kRecentSteps; ++k) {
    substeps.observe(kStep / 3, 0.0001f);
    EXPECT_EQ(substeps.count(kStep, 0.0f, 0.0f, 0.0f, 9.81f), 3) << k << " steps later";
  }
  substeps.observe(kStep / 3, 0.0001f);  // the compressed step has left the window
  EXPECT_GT(substeps.longest_substep(), 0.4f * kStep);
  for (int k = 0; k < 20; ++k) substeps.observe(kStep / 3, 0.0001f);
  EXPECT_EQ(substeps.count(kStep, 0.0f, 0.0f, 0.0f, 9.81f), 1);
}

// A step that left more than half the tolerance holds the bound for kRecentSteps steps, as a
// compressed one does, however little the steps after it show; one that left less says nothing
// against lengthening. At half a step, 0.6 of the tolerance allows 0.65 of a step, 0.4 of it 0.79.
TEST(PbfSubsteps, OnlyAStepPastHalfTheToleranceHoldsTheBound) {
  for (const float share : {0.6f, 0.4f}) {
    SCOPED_TRACE(std::to_string(share) + " of the tolerance");
    PbfSubsteps substeps = rule(1.0f, 0.01f);
    substeps.observe(kStep / 2, share * 0.01f);
    ASSERT_EQ(substeps.count(kStep, 0.0f, 0.0f, 0.0f, 9.81f), 2);
    for (int k = 1; k < PbfSubsteps::kRecentSteps; ++k) substeps.observe(kStep / 2, 0.0001f);
    EXPECT_EQ(substeps.count(kStep, 0.0f, 0.0f, 0.0f, 9.81f), share > 0.5f ? 2 : 1);
  }
}

// Within the tolerance substeps never shorten, and lengthen only as far as would leave 0.7² of it
// by the Δt² rule: 0.13 of the tolerance at half a step would be 0.52 of it at a whole step, 0.11
// would be 0.44. Each held long enough for the compressed step to leave the window and the bound
// to grow as far as it may (after 20 it would have reached only 0.8 of a step, short of where the
// margin stops it, and a margin of 0.85 would pass).
TEST(PbfSubsteps, TheyLengthenWithAMarginBelowTheTolerance) {
  constexpr int kSettled = PbfSubsteps::kRecentSteps + 20;
  PbfSubsteps substeps = rule(1.0f, 0.01f);
  substeps.observe(kStep, 0.04f);
  for (int k = 0; k < kSettled; ++k) substeps.observe(kStep / 2, 0.0013f);
  EXPECT_EQ(substeps.count(kStep, 0.0f, 0.0f, 0.0f, 9.81f), 2);
  for (int k = 0; k < kSettled; ++k) substeps.observe(kStep / 2, 0.0011f);
  EXPECT_EQ(substeps.count(kStep, 0.0f, 0.0f, 0.0f, 9.81f), 1);
  for (int k = 0; k < 20; ++k) substeps.observe(kStep, 0.0095f);
  EXPECT_EQ(substeps.count(kStep, 0.0f, 0.0f, 0.0f, 9.81f), 1);
  substeps.observe(kStep, 0.0105f);
  EXPECT_EQ(substeps.count(kStep, 0.0f, 0.0f, 0.0f, 9.81f), 2);
}

// A step that left the error at the tolerance keeps its count, at every count: the bound is then
// the substep taken, and a step over it is k substeps however float rounds the quotient.
TEST(PbfSubsteps, AStepAtTheToleranceKeepsItsCount) {
  for (int n = 1; n <= SolverParams{}.max_substeps; ++n) {
    PbfSubsteps substeps = rule(1.0f, 0.01f);
    substeps.observe(kStep / static_cast<float>(n), 0.01f);
    EXPECT_EQ(substeps.count(kStep, 0.0f, 0.0f, 0.0f, 9.81f), n) << n << " substeps";
  }
}

// A step cut finer than the bound (by travel, or by steps unseen on a GPU) that leaves the error
// within the tolerance does not shorten the bound, while it reaches no further than the tolerance.
TEST(PbfSubsteps, ASubstepShorterThanTheBoundDoesNotShortenIt) {
  PbfSubsteps substeps = rule(1.0f, 0.01f);
  substeps.observe(kStep, 0.04f);
  ASSERT_FLOAT_EQ(substeps.longest_substep(), kStep / 2);
  substeps.observe(kStep / 3, 0.004f);  // at the tolerance 0.527 of a step, 0.8 of it 0.42
  EXPECT_FLOAT_EQ(substeps.longest_substep(), kStep / 2);
  EXPECT_EQ(substeps.count(kStep, 0.0f, 0.0f, 0.0f, 9.81f), 2);
  substeps.observe(kStep / 3, 0.0048f);  // at the tolerance 0.48 of a step: the bound follows
  EXPECT_LT(substeps.longest_substep(), 0.49f * kStep);
}

// Figures steps old are trusted only while they were well within the tolerance: otherwise each
// step still running counts as one that compressed the fluid 1.3 times more (1.3² = 1.69 for
// four).
TEST(PbfSubsteps, StepsUnseenNearTheBoundTakeMoreSubsteps) {
  PbfSubsteps substeps = rule(1.0f, 0.01f);
  // Nothing observed yet: the bound start() set (here none) stands, unseen steps or not.
  EXPECT_EQ(substeps.count(kStep, 0.0f, 0.0f, 0.0f, 9.81f, 4), 1);
  substeps.observe(kStep, 0.004f);  // well within: unseen steps change nothing
  EXPECT_EQ(substeps.count(kStep, 0.0f, 0.0f, 0.0f, 9.81f, 4), 1);
  substeps.observe(kStep, 0.01f);  // at the tolerance: still one substep, but not when unseen
  EXPECT_EQ(substeps.count(kStep, 0.0f, 0.0f, 0.0f, 9.81f, 0), 1);
  EXPECT_EQ(substeps.count(kStep, 0.0f, 0.0f, 0.0f, 9.81f, 2), 2);
  substeps.observe(kStep, std::numeric_limits<float>::quiet_NaN());  // ignored, as in the bound
  EXPECT_EQ(substeps.count(kStep, 0.0f, 0.0f, 0.0f, 9.81f, 2), 2);
}

// Where lengthening leaves a fluid at rest (0.49 of the tolerance), and well above it (0.64), is
// not near the bound: steps unseen add nothing there, or a deep pool would take more substeps
// whenever steps were in flight and fewer when they were not, and bounce at each switch.
TEST(PbfSubsteps, StepsUnseenAddNothingWhereLengtheningLeavesAFluid) {
  PbfSubsteps substeps = rule(1.0f, 0.01f);
  substeps.observe(kStep / 2, 0.0064f);
  EXPECT_EQ(substeps.count(kStep, 0.0f, 0.0f, 0.0f, 9.81f, 3), 2);
  substeps.observe(kStep / 2, 0.0085f);
  EXPECT_EQ(substeps.count(kStep, 0.0f, 0.0f, 0.0f, 9.81f, 0), 2);
  EXPECT_EQ(substeps.count(kStep, 0.0f, 0.0f, 0.0f, 9.81f, 2), 3);
}

// A fluid just loaded starts from its weight: with c = h √(4 · iterations) / Δt, a column of
// depth H is compressed at its foot by g H / c², which is the tolerance for
// Δt = h √(4 · iterations · tolerance / (g H)).
TEST(PbfSubsteps, AFluidJustLoadedStartsFromItsWeight) {
  PbfSubsteps substeps = rule(1.0f, 0.01f);
  const std::vector<glm::vec3> column = {
      {0.1f, 0.0f, 0.0f}, {0.2f, 0.8f, 0.1f}, {0.0f, 0.3f, 0.2f}};
  const glm::vec3 gravity(0.0f, -9.81f, 0.0f);
  substeps.start(column, gravity);
  const float expected = kH * std::sqrt(4.0f * 4.0f * 0.01f / (9.81f * 0.8f));
  EXPECT_FLOAT_EQ(substeps.longest_substep(), expected);
  EXPECT_EQ(substeps.count(kStep, 0.0f, 0.0f, 0.0f, 9.81f), 2);  // 5.7 ms a substep at most
  // The depth is taken along gravity: tilted to x the same points stand 0.2 m deep.
  substeps.start(column, glm::vec3(9.81f, 0.0f, 0.0f));
  EXPECT_FLOAT_EQ(substeps.longest_substep(), 2.0f * expected);
  // What was observed of the fluid before is forgotten: its figures no longer describe this one.
  substeps.observe(kStep, 0.04f);
  substeps.start(column, gravity);
  EXPECT_FLOAT_EQ(substeps.longest_substep(), expected);
  EXPECT_EQ(substeps.count(kStep, 0.0f, 0.0f, 0.0f, 9.81f, 4), 2);  // and unseen steps add nothing
  // Without weight, or without water, there is no column to press.
  substeps.start(column, glm::vec3(0.0f));
  EXPECT_TRUE(std::isinf(substeps.longest_substep()));
  substeps.start({}, gravity);
  EXPECT_TRUE(std::isinf(substeps.longest_substep()));
}

// A substep keeps the stiffness of the substeps the density bound alone would cut a whole step
// into (its λ and s_corr then taken at (Δt / Δt_s)²): cut finer for travel, or a step of slow
// motion in one short substep, it is no stiffer; one longer than the bound asks (a caller of
// Solver::step that cuts a step coarser than the rule) is as stiff as itself; steps unseen near
// the bound stiffen it as they add substeps; with no bound at all (no compression held) it is as
// stiff as itself. A stiffer substep would release what the fluid holds at its stiffness now as
// velocity.
TEST(PbfSubsteps, OnlyTheDensityBoundStiffensASubstep) {
  PbfSubsteps substeps = rule(1.0f, 0.01f);
  EXPECT_FLOAT_EQ(substeps.stiffness_substep(kStep, kStep / 6), kStep / 6);  // no bound yet
  // The bound: half a step.
  substeps.observe(kStep, 0.04f);
  ASSERT_EQ(substeps.count(kStep, 0.0f, 0.0f, 0.0f, 9.81f), 2);
  EXPECT_FLOAT_EQ(substeps.stiffness_substep(kStep, kStep / 6), kStep / 2);
  EXPECT_FLOAT_EQ(substeps.stiffness_substep(kStep, kStep / 2), kStep / 2);
  EXPECT_FLOAT_EQ(substeps.stiffness_substep(kStep, kStep), kStep);
  // Slow motion: a quarter step in one substep, worked out from the whole step, keeps its
  // stiffness; from the short step's own length (as a caller passing `seconds` would) it would
  // be as stiff as the substep itself.
  EXPECT_FLOAT_EQ(substeps.stiffness_substep(kStep, kStep / 4), kStep / 2);
  EXPECT_FLOAT_EQ(substeps.stiffness_substep(kStep / 4, kStep / 4), kStep / 4);
  EXPECT_FLOAT_EQ(stiffness_share(kStep / 6, kStep / 2), 1.0f / 9.0f);
  // At the tolerance, two steps unseen ask for 2 · 1.3 substeps: 3.
  substeps.observe(kStep / 2, 0.01f);
  EXPECT_FLOAT_EQ(substeps.stiffness_substep(kStep, kStep / 6, 0), kStep / 2);
  EXPECT_FLOAT_EQ(substeps.stiffness_substep(kStep, kStep / 6, 2), kStep / 3);
  EXPECT_EQ(substeps.count(kStep, 0.0f, 0.0f, 0.0f, 9.81f, 2), 3);
}

// A particle pressed past 3 tolerances takes more of its λ than its step's share, all of it past
// 6; one less compressed, or in a step that applies all of its corrections anyway, its step's.
TEST(PbfSubsteps, APressedParticleStiffensAlone) {
  const float tolerance = 0.01f;
  EXPECT_FLOAT_EQ(particle_stiffness_share(0.25f, 0.0f, tolerance), 0.25f);
  EXPECT_FLOAT_EQ(particle_stiffness_share(0.25f, 0.03f, tolerance), 0.25f);
  EXPECT_FLOAT_EQ(particle_stiffness_share(0.25f, 0.045f, tolerance), 0.625f);
  EXPECT_FLOAT_EQ(particle_stiffness_share(0.25f, 0.06f, tolerance), 1.0f);
  EXPECT_FLOAT_EQ(particle_stiffness_share(0.25f, 0.5f, tolerance), 1.0f);
  EXPECT_FLOAT_EQ(particle_stiffness_share(1.0f, 0.0f, tolerance), 1.0f);
  EXPECT_FLOAT_EQ(particle_stiffness_share(0.25f, -0.2f, tolerance), 0.25f);  // stretched
}

TEST(PbfSubsteps, NonFiniteFiguresNeverGiveFewerSubsteps) {
  PbfSubsteps substeps = rule();
  substeps.observe(kStep, 0.04f);
  substeps.observe(kStep, std::numeric_limits<float>::quiet_NaN());
  EXPECT_FLOAT_EQ(substeps.longest_substep(), kStep / 2);
  EXPECT_EQ(substeps.count(kStep, std::numeric_limits<float>::infinity(), 0.0f, 0.0f, 9.81f),
            SolverParams{}.max_substeps);
  EXPECT_EQ(substeps.count(kStep, std::numeric_limits<float>::quiet_NaN(), 0.0f, 0.0f, 9.81f),
            SolverParams{}.max_substeps);
  for (const float approach :
       {std::numeric_limits<float>::infinity(), std::numeric_limits<float>::quiet_NaN()}) {
    EXPECT_EQ(substeps.count(kStep, 1.0f, 0.0f, approach, 9.81f), SolverParams{}.max_substeps);
  }
}

}  // namespace
}  // namespace fluidcast::sim

// Several solvers' steps in one submission: one submission for all, the same fluid as stepping
// each alone, and the GPU time of each shared pass split by particles.
#include "fluidcast/sim/gpu_step_batch.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "../unit/solver_test_support.h"
#include "fluidcast/sim/solver.h"
#include "gpu_test_support.h"

namespace fluidcast::sim {
namespace {

using fluidcast::testing::GpuTest;
using testing::farthest_apart_by_id;

struct Fluid {
  SolverKind kind;
  SceneKind scene;
  int particles;
  int iterations;
};
// Different kinds, sizes and iteration counts: their steps have different numbers of passes.
const Fluid kFluids[] = {{SolverKind::pbf, SceneKind::dam_break, 1000, 4},
                         {SolverKind::pbf, SceneKind::dam_break, 2000, 2},
                         {SolverKind::sph, SceneKind::dam_break, 800, 4}};

std::unique_ptr<Solver> make(const Fluid& fluid, gpu::Context& context, GpuStepBatch* batch) {
  SceneParams scene;
  scene.kind = fluid.scene;
  scene.particles = fluid.particles;
  SolverParams params;
  params.iterations = fluid.iterations;
  return make_gpu_solver(fluid.kind, context, build_scene(scene), params, batch);
}

// Fixed plans (not the solvers' own rules, which read figures that arrive at different times).
constexpr int kSteps = 24;
constexpr int kSubsteps = 2;

class GpuStepBatchTest : public GpuTest {};

TEST_F(GpuStepBatchTest, StepsOfEverySolverGoInOneSubmission) {
  GpuStepBatch batch(context());
  std::vector<std::unique_ptr<Solver>> solvers;
  for (const Fluid& fluid : kFluids) solvers.push_back(make(fluid, context(), &batch));
  const std::uint64_t before = context().last_submitted();
  for (auto& solver : solvers) {
    solver->step(solver->params().time_step, kSubsteps);
    solver->step(solver->params().time_step, kSubsteps);  // two steps of one solver in a row
  }
  EXPECT_EQ(context().last_submitted(), before) << "a shared batch submits only when told";
  batch.submit();
  EXPECT_EQ(context().last_submitted(), before + 1);
  batch.submit();
  EXPECT_EQ(context().last_submitted(), before + 1) << "nothing left to submit";
  for (auto& solver : solvers) {
    solver->synchronize();
    EXPECT_EQ(solver->stage_times().substeps,
              context().timestamps_supported() ? 2u * kSubsteps : 0u);
  }
}

// The PBF density rule counts the steps that have not finished: with its last figures near the
// tolerance (here far above: a pool's first step in one substep against a tolerance of 10⁻⁴; in
// the substeps its start asks it left under half of it, and late figures are then trusted), a
// solver with two steps waiting in the batch plans 1.3 times the substeps it plans with none
// (the rule itself: PbfSubsteps.StepsUnseenNearTheBoundTakeMoreSubsteps). Steps waiting
// unsubmitted are certain not to have finished, as a GPU's fast ones are not.
TEST_F(GpuStepBatchTest, StepsNotYetFinishedCountForThePbfDensityRule) {
  GpuStepBatch batch(context());
  SceneParams scene;
  scene.kind = SceneKind::pool;
  scene.particles = 1000;
  SolverParams params;
  params.pbf_density_tolerance = 1e-4f;
  const auto solver =
      make_gpu_solver(SolverKind::pbf, context(), build_scene(scene), params, &batch);
  const float step = solver->params().time_step;
  solver->step(step, 1);
  batch.submit();
  solver->synchronize();
  const int seen = solver->substeps_for(step);
  solver->step(step, seen);
  solver->step(step, seen);
  EXPECT_GE(solver->substeps_for(step),
            static_cast<int>(std::ceil(1.29f * static_cast<float>(seen))))
      << seen << " substeps with every step seen";
  batch.submit();
  solver->synchronize();
}

TEST_F(GpuStepBatchTest, BatchedStepsGiveTheFluidOfStepsOneByOne) {
  GpuStepBatch batch(context());
  std::vector<std::unique_ptr<Solver>> alone, again, together;
  for (const Fluid& fluid : kFluids) {
    alone.push_back(make(fluid, context(), nullptr));
    again.push_back(make(fluid, context(), nullptr));
    together.push_back(make(fluid, context(), &batch));
  }
  for (int k = 0; k < kSteps; ++k) {
    for (auto* group : {&alone, &again, &together}) {
      for (auto& solver : *group) solver->step(solver->params().time_step, kSubsteps);
    }
    batch.submit();
  }
  for (std::size_t s = 0; s < alone.size(); ++s) {
    SCOPED_TRACE(std::string(to_string(kFluids[s].kind)) + ", " +
                 std::to_string(kFluids[s].particles) + " particles");
    const ParticleSet a = alone[s]->snapshot();
    const double batched = farthest_apart_by_id(a, together[s]->snapshot());
    // Within a cell the sort's order follows atomics, which a GPU may complete in any order, so
    // two runs of the same unbatched steps can round differently and drift apart: that drift is
    // this device's floor. Batched steps must agree with one-by-one ones to a hundredth of a
    // particle spacing, or within a few times the floor where that is larger; a batch that mixed
    // up sessions' ranges or missed a barrier moves particles by spacings. (One pair of runs may
    // happen to round alike, floor 0, while the batched one drifted by 1.05e-3 spacings: lavapipe,
    // once in a full run.)
    const double floor = farthest_apart_by_id(a, again[s]->snapshot());
    const double moved = farthest_apart_by_id(alone[s]->scene().particles, a);
    const double spacing = alone[s]->fluid().spacing;
    std::printf(
        "largest difference %.3g m batched, %.3g m between two unbatched runs; largest "
        "motion %.3g m\n",
        batched, floor, moved);
    EXPECT_LT(batched, std::max(1e-2 * spacing, 8.0 * floor));
    EXPECT_LT(floor, 0.1 * spacing) << "two runs of the same steps drifted apart";
    EXPECT_GT(moved, 2.0 * spacing);
  }
}

TEST_F(GpuStepBatchTest, EachSharedPassIsSplitByParticles) {
  if (!context().timestamps_supported()) GTEST_SKIP() << "no timestamps on this device";
  GpuStepBatch batch(context());
  const auto nothing = [](VkCommandBuffer) {};
  GpuStepBatch::Receipt small, large, later;
  int owner_a = 0, owner_b = 0;
  batch.queue(&owner_a, 100, {{1, 0, nothing}, {2, 0, nothing}}, small);
  batch.queue(&owner_b, 300, {{1, 0, nothing}}, large);
  batch.queue(&owner_a, 100, {{3, 0, nothing}}, later);  // after owner a's first step
  EXPECT_TRUE(batch.holds(&owner_a));
  batch.submit();
  EXPECT_FALSE(batch.holds(&owner_a));
  ASSERT_NE(small.serial, 0u);
  EXPECT_EQ(large.serial, small.serial);
  EXPECT_EQ(later.serial, small.serial);
  ASSERT_EQ(small.passes.size(), 2u);
  ASSERT_EQ(large.passes.size(), 1u);
  ASSERT_EQ(later.passes.size(), 1u);
  // Pass 1: both owners, split 1 : 3. Passes 2 and 3: owner a alone.
  EXPECT_DOUBLE_EQ(small.passes[0].share, 0.25);
  EXPECT_DOUBLE_EQ(large.passes[0].share, 0.75);
  EXPECT_EQ(large.passes[0].from, small.passes[0].from);
  EXPECT_DOUBLE_EQ(small.passes[1].share, 1.0);
  EXPECT_EQ(small.passes[1].stage, 2);
  EXPECT_EQ(later.passes[0].stage, 3);
  EXPECT_EQ(later.passes[0].from, small.passes[1].to);
}

// More passes than the timestamps a submission holds (many steps of many substeps in one tick):
// still timed, in groups of consecutive passes, each pass an equal part of its group, so the steps'
// shares still add up to the whole submission's time.
TEST_F(GpuStepBatchTest, MorePassesThanTimestampsAreTimedInGroups) {
  if (!context().timestamps_supported()) GTEST_SKIP() << "no timestamps on this device";
  GpuStepBatch batch(context());
  const auto nothing = [](VkCommandBuffer) {};
  constexpr std::size_t kPasses = 2 * GpuStepBatch::kTimestampCapacity + 4;
  std::vector<GpuStepBatch::Pass> long_step(kPasses, {1, 0, nothing});
  GpuStepBatch::Receipt alone, beside;
  int owner_a = 0, owner_b = 0;
  batch.queue(&owner_a, 100, std::move(long_step), alone);
  batch.queue(&owner_b, 300, {{2, 0, nothing}}, beside);
  batch.submit();
  ASSERT_TRUE(alone.timestamps) << "a long submission went untimed";
  ASSERT_EQ(alone.passes.size(), kPasses);
  ASSERT_EQ(beside.passes.size(), 1u);
  const std::uint32_t groups = alone.passes.back().to;  // the marks after the first
  EXPECT_LT(groups, GpuStepBatch::kTimestampCapacity);
  EXPECT_EQ(groups, (kPasses + 2) / 3) << "groups of three passes";
  double shares = beside.passes[0].share;
  for (const GpuStepBatch::Receipt::Timed& pass : alone.passes) {
    EXPECT_EQ(pass.to, pass.from + 1);
    shares += pass.share;
  }
  EXPECT_NEAR(shares, double(groups), 1e-9) << "every group's time is handed out whole";
  // The first group: both owners in its first pass (1 : 3), owner a alone in the other two.
  EXPECT_DOUBLE_EQ(alone.passes[0].share, 0.25 / 3);
  EXPECT_DOUBLE_EQ(beside.passes[0].share, 0.75 / 3);
  EXPECT_DOUBLE_EQ(alone.passes[1].share, 1.0 / 3);
  EXPECT_DOUBLE_EQ(alone.passes.back().share, 1.0 / 2) << "the last group is two passes";
  context().wait_for(alone.serial);
  alone.timestamps->fetch();
  double handed_out = 0.0;
  for (const auto& pass : alone.passes) {
    handed_out += alone.timestamps->elapsed_ms(pass.from, pass.to) * pass.share;
  }
  handed_out += alone.timestamps->elapsed_ms(beside.passes[0].from, beside.passes[0].to) *
                beside.passes[0].share;
  EXPECT_NEAR(handed_out, alone.timestamps->elapsed_ms(0, groups), 1e-6);
}

TEST_F(GpuStepBatchTest, ASolverThatGoesAwayTakesItsWaitingStepsWithIt) {
  GpuStepBatch batch(context());
  auto solver = make(kFluids[0], context(), &batch);
  solver->step(solver->params().time_step, kSubsteps);
  EXPECT_TRUE(batch.holds(solver.get()));
  const std::uint64_t before = context().last_submitted();
  const Solver* gone = solver.get();
  solver.reset();
  EXPECT_FALSE(batch.holds(gone));
  batch.submit();
  EXPECT_EQ(context().last_submitted(), before);
}

// As a retired solver that the context releases after the server's hub (and its batch) has gone.
TEST_F(GpuStepBatchTest, ASolverWhoseStepsWereSubmittedMayOutliveItsBatch) {
  std::unique_ptr<Solver> solver;
  {
    GpuStepBatch batch(context());
    solver = make(kFluids[0], context(), &batch);
    solver->step(solver->params().time_step, kSubsteps);
    batch.submit();
  }
  solver.reset();
}

TEST_F(GpuStepBatchTest, ASnapshotSubmitsTheStepsItMustSee) {
  GpuStepBatch batch(context());
  auto solver = make(kFluids[0], context(), &batch);
  const ParticleSet start = solver->snapshot();
  for (int k = 0; k < kSteps; ++k) solver->step(solver->params().time_step, kSubsteps);
  const ParticleSet later = solver->snapshot();  // no batch.submit(): the snapshot does it
  EXPECT_FALSE(batch.holds(solver.get()));
  EXPECT_GT(farthest_apart_by_id(start, later), solver->fluid().spacing);
}

}  // namespace
}  // namespace fluidcast::sim

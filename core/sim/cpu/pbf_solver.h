// Position Based Fluids: Macklin & Müller, "Position Based Fluids", ACM TOG 32(4), 2013.
// A step is split into substeps by PbfSubsteps (substeps.h): short enough that nothing travels
// more than pbf_travel·h in one and that the compression the last step left stays within
// tolerance. A substep: predict → neighbour search on predicted positions (sorted, reordered) →
// Jacobi iterations of the density constraint (λ, then Δp with s_corr and collisions) → velocity
// from the displacement; the step's last substep then smooths and confines the velocity (XSPH
// viscosity and vorticity confinement, once a step: pbf_step_xsph) and measures the compression.
//
// Five choices beyond the paper: the density constraint is unilateral, C = max(ρ/ρ0 − 1, 0), so
// a surface particle with few neighbours is not pulled inwards; ε and s_corr are scaled by the
// rest-state Σ|∇C|², which makes them dimensionless and independent of the particle size; the
// velocity the corrections add is capped (pbf_max_acceleration, as NVIDIA FleX's maxAcceleration);
// the first and last iterations' corrections are weighted (pbf_correction_weight); and a step cut
// finer than its density bound asks keeps that bound's stiffness (PbfSubsteps::stiffness_substep).
#pragma once

#include "cpu/cpu_solver.h"
#include "substeps.h"

namespace fluidcast::sim::cpu {

class PbfSolver final : public CpuSolver {
 public:
  PbfSolver(Scene scene, const SolverParams& params, std::shared_ptr<ForkJoinPool> pool);
  SolverKind kind() const override { return SolverKind::pbf; }

 private:
  int substeps_for(float seconds) override;
  // A fluid loaded here starts the substep rule afresh (PbfSubsteps::start).
  void load_particles(const ParticleSet& particles) override;
  int advance(float seconds, int substeps) override;
  void substep();
  // The step's last substep, after its iterations: XSPH and vorticity confinement over the step
  // of `substeps` substeps, and the compression it leaves, for the substep rule.
  void finish_step(int substeps);
  void predict();
  void compute_lambdas();
  // Moves each particle by `weight` times its Δp (pbf_correction_weight); the last iteration also
  // sets the velocities from the corrected positions.
  void apply_position_corrections(float weight, bool set_velocities);
  // The share of the corrections this step applies to keep its density bound's stiffness
  // (stiffness_share()): λ by particle_stiffness_share(), s_corr by the step's share alone.
  float step_stiffness() const { return stiffness_share(dt_, stiffness_dt_); }
  glm::vec3 velocity_from(std::size_t i, glm::vec3 corrected) const;
  // XSPH's smoothing by `xsph`, the curl where confinement is on, and the compression.
  void sum_over_neighbours(float xsph);
  bool confines_vorticity() const { return params().vorticity > 0.0f; }
  // Over `seconds`, onto the smoothed velocity.
  void confine_vorticity(float seconds);
  // Mean over particles of max(ρ/ρ0 − 1, 0) at the corrected positions, walls included, as the
  // step's last sum_over_neighbours() measured it: what the step leaves, for the substep rule.
  float average_compression() const;

  float relaxation_epsilon_;  // ε, absolute
  float scorr_scale_;         // k / Σ|∇C|²_rest
  float inv_w_dq_;            // 1 / W(Δq)
  float dt_ = 0.0f;           // of the current substep
  float stiffness_dt_ = 0.0f;  // PbfSubsteps::stiffness_substep() of the current substep
  PbfSubsteps substeps_;
  std::vector<float> compression_;  // per particle, at the end of the step
  std::vector<glm::vec3> predicted_, corrected_;
  std::vector<glm::vec3> uncorrected_;  // predicted_ before the density corrections
  std::vector<float> lambda_;
  std::vector<glm::vec3> vorticity_, smoothed_velocity_;
  std::vector<float> vorticity_norm_;
  // Per neighbour pair, lanes::kWidth pairs a block (NeighbourList::blocks_of): ∇W_spiky and
  // W_poly6, computed by compute_lambdas (and sum_over_neighbours) and reused by the pass after it,
  // which sees the same positions. The lanes past a list hold zeros.
  struct PairBlock {
    lanes::Vec3 gradient;
    lanes::Floats poly6;
  };
  // The kernels between i and the block of its neighbours at list + k, at the predicted positions.
  [[gnu::always_inline]] PairBlock kernels_of_block(std::size_t i,
                                                    std::span<const std::uint32_t> list,
                                                    std::size_t k) const {
    const lanes::Vec3 r = offsets(predicted_.data(), i, list, k);
    const lanes::Floats r2 = lanes::dot(r, r);
    return {kernels_.spiky_gradient(r, r2), kernels_.poly6(r2)};
  }
  std::vector<PairBlock> pair_blocks_;
  PairBlock* first_block(std::size_t i) {
    return pair_blocks_.data() + neighbours_.first_pair(i) / lanes::kWidth;
  }
};

}  // namespace fluidcast::sim::cpu

#include "cpu/pbf_solver.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "pbf_constants.h"
#include "substeps.h"

namespace fluidcast::sim::cpu {

PbfSolver::PbfSolver(Scene scene, const SolverParams& params, std::shared_ptr<ForkJoinPool> pool)
    : CpuSolver(std::move(scene), params, std::move(pool)), substeps_(params, kernels_.radius()) {
  const PbfConstants constants = derive_pbf_constants(params, fluid());
  relaxation_epsilon_ = constants.relaxation_epsilon;
  scorr_scale_ = constants.scorr_scale;
  inv_w_dq_ = constants.inv_w_dq;
  // CpuSolver's constructor loaded the scene before this override existed.
  substeps_.start(particles_.position, gravity());
}

void PbfSolver::load_particles(const ParticleSet& particles) {
  CpuSolver::load_particles(particles);
  substeps_.start(particles.position, gravity());
}

int PbfSolver::substeps_for(float seconds) {
  const float approach =
      largest_wall_approach(particles_.position, particles_.velocity, inner_tank(), seconds);
  return substeps_.count(seconds, max_speed(), max_collider_speed(), approach,
                         glm::length(gravity()));
}

int PbfSolver::advance(float seconds, int substeps) {
  dt_ = seconds / static_cast<float>(substeps);
  stiffness_dt_ = substeps_.stiffness_substep(params().time_step, dt_);
  for (int s = 0; s < substeps; ++s) {
    set_time_into_step(static_cast<float>(s + 1) * dt_);  // predicted positions are at its end
    substep();
    if (s + 1 == substeps) finish_step(substeps);
    particles_.position.swap(predicted_);
  }
  return substeps;
}

void PbfSolver::substep() {
  ++stage_times_.substeps;
  {
    StageTimer timer(stage_times_.predict_ms);
    predict();
  }
  {
    StageTimer timer(stage_times_.grid_ms);
    sort_by(predicted_, {&predicted_});
  }
  {
    StageTimer timer(stage_times_.neighbours_ms);
    list_neighbours(predicted_);
  }
  uncorrected_ = predicted_;
  const int iterations = params().iterations;
  stage_times_.iteration_ms.resize(static_cast<std::size_t>(iterations));
  for (int iteration = 0; iteration < iterations; ++iteration) {
    double& iteration_ms = stage_times_.iteration_ms[static_cast<std::size_t>(iteration)];
    const double before = iteration_ms;
    {
      StageTimer timer(iteration_ms);
      compute_lambdas();
      apply_position_corrections(pbf_correction_weight(params(), iteration),
                                 iteration + 1 == iterations);
    }
    stage_times_.solve_ms += iteration_ms - before;
  }
}

void PbfSolver::finish_step(int substeps) {
  {
    StageTimer timer(stage_times_.velocity_ms);
    sum_over_neighbours(pbf_step_xsph(params(), substeps));
  }
  {
    StageTimer timer(stage_times_.viscosity_ms);
    // As the GPU's finish pass: the step's length as its substeps add up.
    if (confines_vorticity()) confine_vorticity(static_cast<float>(substeps) * dt_);
    particles_.velocity.swap(smoothed_velocity_);
    // The filters may add speed: held as the GPU's finish pass holds it (pbf_finish.comp).
    pool_->for_each(particles_.size(), [&](std::size_t i) {
      particles_.velocity[i] = held_to_max_speed(particles_.velocity[i]);
    });
  }
  substeps_.observe(stiffness_dt_, average_compression());
}

void PbfSolver::predict() {
  const std::size_t n = particles_.size();
  predicted_.resize(n);
  const float dt = dt_;
  const glm::vec3 dv = gravity() * dt;
  const float limit2 = substeps_.speed_limit(dt) * substeps_.speed_limit(dt);
  pool_->for_each(n, [&](std::size_t i) {
    glm::vec3& v = particles_.velocity[i];
    v += dv;
    const float speed2 = glm::dot(v, v);
    if (speed2 > limit2) v *= std::sqrt(limit2 / speed2);
    predicted_[i] = constrain_position(particles_.position[i] + dt * particles_.velocity[i]);
  });
}

void PbfSolver::compute_lambdas() {
  const std::size_t n = particles_.size();
  lambda_.resize(n);
  const float mass = fluid().particle_mass;
  const float inv_rest_density = 1.0f / fluid().rest_density;
  const float volume = fluid().rest_volume();
  const float self_density = kernels_.poly6(0.0f);
  const float stiffness = step_stiffness();
  const float tolerance = params().pbf_density_tolerance;
  pair_blocks_.resize(neighbours_.pair_count() / lanes::kWidth);
  pool_->for_each(n, [&](std::size_t i) {
    const glm::vec3 p = predicted_[i];
    lanes::Floats density{};
    lanes::Vec3 gradient{};
    lanes::Floats sum_squares{};
    PairBlock* block = first_block(i);
    const auto list = neighbours_.blocks_of(i);
    for (std::size_t k = 0; k < list.size(); k += lanes::kWidth, ++block) {
      *block = kernels_of_block(i, list, k);
      density += block->poly6;
      gradient += block->gradient;  // V times both sums, once below
      sum_squares += lanes::dot(block->gradient, block->gradient);
    }
    const auto wall = walls(p);
    const glm::vec3 gradient_i = volume * lanes::sum(gradient) + inv_rest_density * wall.gradient;
    const float constraint = std::max(
        (mass * (self_density + lanes::sum(density)) + wall.density) * inv_rest_density - 1.0f,
        0.0f);
    lambda_[i] = constraint == 0.0f
                     ? 0.0f
                     : -particle_stiffness_share(stiffness, constraint, tolerance) * constraint /
                           (volume * volume * lanes::sum(sum_squares) +
                            glm::dot(gradient_i, gradient_i) + relaxation_epsilon_);
  });
}

float PbfSolver::average_compression() const {
  if (compression_.empty()) return 0.0f;
  const double sum = std::accumulate(compression_.begin(), compression_.end(), 0.0);
  return static_cast<float>(sum / static_cast<double>(compression_.size()));
}

void PbfSolver::apply_position_corrections(float weight, bool set_velocities) {
  const std::size_t n = particles_.size();
  corrected_.resize(n);
  const float volume = fluid().rest_volume();
  const float inv_rest_density = 1.0f / fluid().rest_density;
  // s_corr at the step's stiffness, as λ is (compute_lambdas).
  const float scorr_scale = step_stiffness() * scorr_scale_;
  const float exponent = params().scorr_exponent;
  const bool exponent_is_four = exponent == 4.0f;
  pool_->for_each(n, [&](std::size_t i) {
    const glm::vec3 p = predicted_[i];
    const float lambda_i = lambda_[i];
    lanes::Vec3 delta{};
    const PairBlock* block = first_block(i);
    const auto list = neighbours_.blocks_of(i);
    for (std::size_t k = 0; k < list.size(); k += lanes::kWidth, ++block) {
      const lanes::Floats s = block->poly6 * inv_w_dq_;
      lanes::Floats s_power = (s * s) * (s * s);
      if (!exponent_is_four)
        for (std::uint32_t lane = 0; lane < lanes::kWidth; ++lane)
          s_power[lane] = std::pow(s[lane], exponent);
      const lanes::Floats factor =
          lambda_i + lanes::gather(lambda_.data(), list.data() + k) - scorr_scale * s_power;
      delta += factor * block->gradient;
    }
    // The walls hold no λ of their own: only this particle's constraint pushes it off them.
    const glm::vec3 wall_push = lambda_i * inv_rest_density * walls(p).gradient;
    corrected_[i] = constrain_position(p + weight * (volume * lanes::sum(delta) + wall_push));
    if (set_velocities) particles_.velocity[i] = velocity_from(i, corrected_[i]);
  });
  predicted_.swap(corrected_);
}

// v = (x* − x) / Δt, but the corrections' part of it, (x* − x*uncorrected) / Δt, is capped at
// pbf_max_acceleration · Δt: compression that earlier substeps left behind would otherwise come
// back as velocity that grows as the substeps shorten (a burst) instead of being smoothed out.
glm::vec3 PbfSolver::velocity_from(std::size_t i, glm::vec3 corrected) const {
  const float inv_dt = 1.0f / dt_;
  const float most = params().pbf_max_acceleration * dt_;
  const glm::vec3 uncorrected = (uncorrected_[i] - particles_.position[i]) * inv_dt;
  const glm::vec3 change = (corrected - uncorrected_[i]) * inv_dt;
  const float length = glm::length(change);
  return held_to_max_speed(uncorrected + (length > most ? change * (most / length) : change));
}

// At the corrected positions and velocities: with vorticity confinement on, ω_i = Σ_j V (v_j − v_i)
// × ∇_j W_ij, the SPH estimate of the curl of the velocity; XSPH's v_i + c Σ_j V (v_j − v_i) W_ij
// with c = `xsph`; and the compression max(ρ/ρ0 − 1, 0), walls included. One pass: the same
// kernels serve all three.
void PbfSolver::sum_over_neighbours(float xsph) {
  const std::size_t n = particles_.size();
  const bool confine = confines_vorticity();
  vorticity_.resize(confine ? n : 0);
  vorticity_norm_.resize(confine ? n : 0);
  smoothed_velocity_.resize(n);
  compression_.resize(n);
  pair_blocks_.resize(neighbours_.pair_count() / lanes::kWidth);
  const float volume = fluid().rest_volume();
  const float mass = fluid().particle_mass;
  const float inv_rest_density = 1.0f / fluid().rest_density;
  const float self_density = kernels_.poly6(0.0f);
  const glm::vec3* v = particles_.velocity.data();
  pool_->for_each(n, [&](std::size_t i) {
    lanes::Vec3 omega{};
    lanes::Vec3 smoothing{};
    lanes::Floats density{};
    PairBlock* block = first_block(i);
    const auto list = neighbours_.blocks_of(i);
    for (std::size_t k = 0; k < list.size(); k += lanes::kWidth, ++block) {
      *block = kernels_of_block(i, list, k);
      const lanes::Vec3 relative = lanes::gather(v, list.data() + k) - v[i];
      // ∇_j W_ij = −∇_i W_ij
      if (confine) omega += lanes::cross(relative, block->gradient);
      smoothing += block->poly6 * relative;
      density += block->poly6;
    }
    if (confine) {
      vorticity_[i] = -volume * lanes::sum(omega);
      vorticity_norm_[i] = glm::length(vorticity_[i]);
    }
    smoothed_velocity_[i] = v[i] + xsph * volume * lanes::sum(smoothing);
    compression_[i] = std::max(
        (mass * (self_density + lanes::sum(density)) + walls(predicted_[i]).density) *
                inv_rest_density -
            1.0f,
        0.0f);
  });
}

// Vorticity confinement a = ε N × ω with N = ∇|ω| / |∇|ω||, onto the XSPH-smoothed velocity.
void PbfSolver::confine_vorticity(float seconds) {
  const float epsilon = params().vorticity;
  pool_->for_each(particles_.size(), [&](std::size_t i) {
    const float omega_i = vorticity_norm_[i];
    lanes::Vec3 eta{};
    const PairBlock* block = first_block(i);
    const auto list = neighbours_.blocks_of(i);
    for (std::size_t k = 0; k < list.size(); k += lanes::kWidth, ++block) {
      eta += (lanes::gather(vorticity_norm_.data(), list.data() + k) - omega_i) * block->gradient;
    }
    const glm::vec3 eta_sum = lanes::sum(eta);
    const float eta_length = glm::length(eta_sum);
    if (eta_length > 1e-12f)
      smoothed_velocity_[i] += seconds * epsilon * glm::cross(eta_sum / eta_length, vorticity_[i]);
  });
}

}  // namespace fluidcast::sim::cpu

// PBF and SPH entirely in Vulkan compute. The particles stay on the GPU: each step is a list of
// passes (parameters, then every substep's grid build, reorder and solver passes) that a
// GpuStepBatch records, alone or interleaved with other solvers' steps, and the host reads
// positions and velocities back only for a snapshot. Four steps may be in flight; the
// substep count of a step comes from the largest speed (for SPH also acceleration, for PBF the
// compression left) of the newest finished step, which the GPU records with one atomic per
// workgroup.
// The formulas are the CPU solvers' (cpu/pbf_solver.cpp, cpu/sph_solver.cpp): see there for the
// papers, and the neighbours are listed once per substep as the CPU solvers list them (within h at
// the substep's start, at most FluidConstants::max_neighbours each). One difference: SPH
// substeps are equal within a step, as their count is recorded up front, where the CPU solver
// adapts each substep to the state it has just computed.
#pragma once

#include <array>
#include <memory>
#include <optional>

#include "fluidcast/gpu/compute_pipeline.h"
#include "fluidcast/sim/gpu_neighbour_grid.h"
#include "fluidcast/sim/gpu_solver_statistics.h"
#include "fluidcast/sim/gpu_step_batch.h"
#include "fluidcast/sim/solver.h"
#include "gpu/gpu_sim_params.h"
#include "substeps.h"

namespace fluidcast::sim::gpu_solver {

class GpuSolver final : public Solver {
 public:
  // Throws ParamError as Solver does, and ParamError when the particles would not fit in the
  // memory budget (naming it): 90 % of the device's local memory unless one is given, for an
  // operator who runs several simulations on one device.
  // `batch`: where its steps wait to be submitted with other solvers' (see gpu_step_batch.h);
  // none: a batch of its own, submitted at each step.
  GpuSolver(SolverKind kind, gpu::Context& context, Scene scene, const SolverParams& params,
            GpuStepBatch* batch = nullptr, std::uint64_t memory_budget_bytes = 0);
  // Waits for its steps still running (a retired solver has none left).
  ~GpuSolver() override;

  SolverKind kind() const override { return kind_; }
  std::size_t particle_count() const override { return count_; }
  ParticleSet snapshot() const override;
  void synchronize() override;
  void count_finished_steps() override;
  int substeps_for(float seconds) override;
  std::optional<DeviceParticles> device_particles() const override {
    return DeviceParticles{buffers_.position.address(), buffers_.velocity.address(),
                           buffers_.density_ratio.address()};
  }

  // GPU memory needed for `particles`, and how many fit: in the budget, in the neighbour lists'
  // index (particles_listable: 2^31 elements of four entries, 15.9 million particles at kernel
  // ratio 4), and in the one buffer that holds the lists, no larger than the device allocates in
  // one piece (lavapipe: 2 GiB, 994 thousand particles at ratio 4).
  std::uint64_t bytes_needed(std::size_t particles) const;
  std::size_t particles_that_fit() const;
  std::size_t particles_listable() const;
  std::size_t particles_listed_in_one_allocation() const;

  // How far ahead, s, a particle closing on a wall counts for the substep rule: the figures that
  // plan a step may be as many steps old as run at once, and the step itself comes after.
  float wall_reach() const { return params().time_step * static_cast<float>(kStepsInFlight + 1); }

  // gpu_solver_pipeline_statistics (gpu_solver_statistics.h).
  static std::vector<PassStatistics> pipeline_statistics(gpu::Context& context);

 protected:
  int advance(float seconds, int substeps) override;
  void append_particles(std::span<const glm::vec3> positions, std::span<const glm::vec3> velocities,
                        std::uint32_t first_id) override;
  std::size_t erase_particles_in_sphere(glm::vec3 centre, float radius) override;
  // A fluid loaded here starts the substep rule afresh (PbfSubsteps::start).
  void load_particles(const ParticleSet& particles) override;

 private:
  // Replaces the particles on the GPU: a loaded fluid, or this one with some added or erased.
  void upload_particles(const ParticleSet& particles);
  enum class Stage { grid, neighbours, predict, iteration, velocity, viscosity, solve };
  struct InFlight {
    explicit InFlight(gpu::Context& context);
    gpu::Buffer stats;  // readback: StatsSlot
    GpuStepBatch::Receipt receipt;
    int substeps = 0;
    float stiffness_substep = 0.0f;  // PBF: PbfSubsteps::stiffness_substep(), for observe()
    std::size_t particles = 0;
    bool harvested = true;     // idle, or its figures are counted
    bool stale_stats = false;  // the particles were replaced while it ran
    bool finished(std::uint64_t last_finished) const {
      return receipt.serial != 0 && receipt.serial <= last_finished;
    }
  };
  struct Pipelines {
    explicit Pipelines(gpu::Context& context);
    gpu::ComputePipeline predict, reorder, neighbours, pbf_lambda, pbf_correct, pbf_sums,
        pbf_finish, sph_force, sph_integrate;
  };

  struct Buffers {
    gpu::Buffer position, velocity, id, sorted_position, sorted_velocity, sorted_id;
    gpu::Buffer predicted, iterate, iterate_scalar, vorticity;  // PBF
    gpu::Buffer density, acceleration;                          // SPH
    gpu::Buffer density_ratio;                                  // both, for the renderer
    gpu::Buffer neighbours, neighbour_count;                    // both: this substep's lists
    std::size_t capacity = 0;
  };
  // Buffers for `capacity` particles, and the grid's room for them; the solver's own are not
  // touched. Throws ParamError beyond the budget, VulkanError when the memory is not there.
  Buffers allocate(std::size_t capacity);
  // Buffers for `n` particles, with room to grow (so that adding a few at a time does not
  // reallocate every time) where the memory allows.
  Buffers allocate_for(std::size_t n);
  // The parameter block of a step of `substeps` substeps whose corrections keep `stiffness` of
  // themselves (PBF: stiffness_share()).
  SimParams step_params(int substeps, float stiffness) const;
  void set_addresses(SimParams& p) const;  // every buffer the shaders read or write
  // Submits this solver's steps still waiting in the batch, so that what follows in the queue
  // (uploads, downloads, waits) comes after them.
  void submit_queued() const;
  using Passes = std::vector<GpuStepBatch::Pass>;
  // `last`: the step's last substep, which measures the compression for the substep rule (and
  // leaves the grid uncleared: the next step's first pass clears it).
  void append_pbf_substep(Passes& passes, const SimPass& pass, bool last) const;
  // Steps queued or submitted whose GPU work has not finished yet.
  int steps_running() const;
  // `then_clear_grid`: the integration pass also clears the grid for the next substep's build.
  void append_sph_substep(Passes& passes, const SimPass& pass, bool then_clear_grid) const;
  // Reads the stats and timestamps of a finished slot, once.
  void harvest(InFlight& slot);

  SolverKind kind_;
  gpu::Context* context_;
  std::unique_ptr<GpuStepBatch> own_batch_;  // when none is shared
  GpuStepBatch* batch_;
  std::uint64_t memory_budget_;
  GpuNeighbourGrid grid_;
  Pipelines pipelines_;
  std::size_t count_ = 0;
  Buffers buffers_;
  gpu::Buffer params_buffer_, stats_buffer_;
  // Steps in flight, a ring: a frame loop may submit this many in one tick without waiting.
  static constexpr std::size_t kStepsInFlight = 4;
  std::array<InFlight, kStepsInFlight> in_flight_;
  std::size_t next_slot_ = 0;
  // From the newest finished step (or the loaded particles).
  float largest_speed_ = 0.0f;
  float largest_wall_approach_ = 0.0f;  // PBF
  float largest_acceleration_ = 0.0f;
  PbfSubsteps pbf_substeps_;
  // PBF constants, derived as the CPU solver does.
  float relaxation_epsilon_ = 0.0f, scorr_scale_ = 0.0f, inv_w_dq_ = 0.0f;
};

}  // namespace fluidcast::sim::gpu_solver

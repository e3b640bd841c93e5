// State and machinery shared by the CPU solvers: the particles, the thread pool, the grid and the
// neighbour lists, and the boundary handling. Every per-particle array is reordered in sort_by().
#pragma once

#include <chrono>
#include <initializer_list>
#include <memory>
#include <span>

#include "fluidcast/sim/fork_join_pool.h"
#include "fluidcast/sim/kernels.h"
#include "fluidcast/sim/neighbour_grid.h"
#include "fluidcast/sim/neighbour_list.h"
#include "fluidcast/sim/solver.h"

namespace fluidcast::sim::cpu {

class CpuSolver : public Solver {
 public:
  // `pool`: null for a pool of its own (params.threads); see make_cpu_solver.
  CpuSolver(Scene scene, const SolverParams& params, std::shared_ptr<ForkJoinPool> pool);

  std::size_t particle_count() const override { return particles_.size(); }
  ParticleSet snapshot() const override { return particles_; }

 protected:
  void append_particles(std::span<const glm::vec3> positions, std::span<const glm::vec3> velocities,
                        std::uint32_t first_id) override;
  std::size_t erase_particles_in_sphere(glm::vec3 centre, float radius) override;
  void load_particles(const ParticleSet& particles) override;

  // Sorts the particles by the cells of `key` and reorders particles_ and every array in
  // `solver_arrays` (which must hold `key` unless key is particles_.position).
  void sort_by(std::vector<glm::vec3>& key,
               std::initializer_list<std::vector<glm::vec3>*> solver_arrays);
  // Lists each particle's neighbours within h at `sorted` (positions in the order sort_by left).
  void list_neighbours(std::span<const glm::vec3> sorted);

  // What the six tank walls add at p, modelled as fluid at rest behind each wall from
  // fluid().wall_offset behind it (Kernels::walls): the density, and its gradient.
  struct WallContribution {
    float density = 0.0f;      // kg/m³
    glm::vec3 gradient{0.0f};  // ∇ of density, pointing into the walls
  };
  WallContribution walls(glm::vec3 p) const {
    const Kernels::WallShare share =
        kernels_.walls(p - wall_fluid_box_.min, wall_fluid_box_.max - p);
    return {fluid().rest_density * share.volume, fluid().rest_density * share.gradient};
  }

  // positions[i] − positions[j] for the block of i's neighbours at list + k (list is
  // neighbours_.blocks_of(i)); its lanes past the list are put 2h away, where every kernel is 0.
  // Inlined by force: GCC called it, and the result's round trip through memory was a third of
  // PBF's vorticity pass.
  [[gnu::always_inline]] lanes::Vec3 offsets(const glm::vec3* positions, std::size_t i,
                                             std::span<const std::uint32_t> list,
                                             std::size_t k) const {
    lanes::Vec3 r = positions[i] - lanes::gather(positions, list.data() + k);
    const auto listed = static_cast<std::int32_t>(neighbours_.of(i).size() - k);
    r.x =
        lanes::select(lanes::kLaneIndex < listed, r.x, lanes::Floats{} + 2.0f * kernels_.radius());
    return r;
  }

  // Σ_j W_poly6(|x_i − x_j|) over i's neighbours j at `positions` (i itself not included).
  float neighbour_poly6_sum(const glm::vec3* positions, std::size_t i) const {
    lanes::Floats sum{};
    const auto list = neighbours_.blocks_of(i);
    for (std::size_t k = 0; k < list.size(); k += lanes::kWidth) {
      const lanes::Vec3 r = offsets(positions, i, list, k);
      sum += kernels_.poly6(lanes::dot(r, r));
    }
    return lanes::sum(sum);
  }

  // The largest |v| over all particles (0 when there are none).
  float max_speed();

  // Seconds into the current step, for where the colliders are now.
  void set_time_into_step(float seconds) { time_into_step_ = seconds; }
  float max_collider_speed() const;

  // Moves p out of every collider and into the tank (shrunk by a particle radius).
  glm::vec3 constrain_position(glm::vec3 p) const;
  // The same, and removes the velocity component into the surface it was pushed out of.
  void constrain_position_and_velocity(glm::vec3& p, glm::vec3& v) const;

  // Adds the wall-clock time of its scope to one StageTimes field.
  class StageTimer {
   public:
    explicit StageTimer(double& total_ms)
        : total_ms_(total_ms), start_(std::chrono::steady_clock::now()) {}
    ~StageTimer() {
      total_ms_ +=
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start_)
              .count();
    }
    StageTimer(const StageTimer&) = delete;
    StageTimer& operator=(const StageTimer&) = delete;

   private:
    double& total_ms_;
    std::chrono::steady_clock::time_point start_;
  };

  ParticleSet particles_;
  std::shared_ptr<ForkJoinPool> pool_;
  Kernels kernels_;
  NeighbourGrid grid_;
  NeighbourList neighbours_;

 private:
  Box inner_tank_;      // inner_tank(), kept: every particle is constrained to it every pass
  Box wall_fluid_box_;  // fluid().wall_fluid_box(tank()), kept: every density reads it
  float time_into_step_ = 0.0f;
  std::vector<glm::vec3> reorder_scratch_;
  std::vector<std::uint32_t> id_scratch_;
  std::vector<float> chunk_max_;
};

}  // namespace fluidcast::sim::cpu

#include "gpu/gpu_solver.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <utility>

#include "fluidcast/gpu/transfer.h"
#include "fluidcast/gpu/vk_check.h"
#include "fluidcast/sim/kernels.h"
#include "fluidcast_shaders/fluidcast_sim.h"
#include "pbf_constants.h"
#include "substeps.h"

namespace fluidcast::sim::gpu_solver {
namespace {

constexpr std::uint32_t kGroup = GpuNeighbourGrid::kGroupSize;
static_assert(kGroup <= 128, "record_sum (sim_kernels.glsl) sums a workgroup in 32 bits");
// Of the device-local heap, what a simulation may plan to use: the driver and other work need some.
constexpr double kUsableMemoryShare = 0.9;
// The shaders read a neighbour list four entries to an element (neighbour_group in
// sim_kernels.glsl), which they index with a 32-bit index that SPIR-V may take as signed.
constexpr std::uint32_t kEntriesPerListElement = 4;
constexpr std::uint64_t kMostListElements = 0x7fffffff;

std::uint64_t list_elements(std::uint32_t max_neighbours) {
  return (std::uint64_t{max_neighbours} + kEntriesPerListElement - 1) / kEntriesPerListElement;
}

// A particle's share of the neighbour lists: the largest buffer there is a share of.
std::uint64_t list_bytes_per_particle(std::uint32_t max_neighbours) {
  return 4 * kEntriesPerListElement * list_elements(max_neighbours);
}

std::uint64_t bytes_per_particle(SolverKind kind, std::uint32_t max_neighbours) {
  // position, velocity, id, their sorted copies, and the density ratio for the renderer
  constexpr std::uint64_t state = 2 * (16 + 16 + 4) + 4;
  constexpr std::uint64_t pbf = 16 + 16 + 16 + 16;  // predicted, iterate, iterate_scalar, ω
  constexpr std::uint64_t sph = 8 + 16;             // density and pressure, acceleration
  const std::uint64_t list = list_bytes_per_particle(max_neighbours) + 4;  // and its length
  return state + (kind == SolverKind::pbf ? pbf : sph) + list +
         GpuNeighbourGrid::bytes_per_particle();
}

float float_from_bits(std::uint32_t bits) {
  float value;
  std::memcpy(&value, &bits, sizeof value);
  return value;
}

}  // namespace

GpuSolver::InFlight::InFlight(gpu::Context& context)
    : stats(context, kStatsSlots * sizeof(std::uint32_t), gpu::MemoryDomain::readback) {}

GpuSolver::Pipelines::Pipelines(gpu::Context& c)
    : predict(c, shaders::sim_predict_comp, sizeof(SimPass), kGroup),
      reorder(c, shaders::sim_reorder_comp, sizeof(SimPass), kGroup),
      neighbours(c, shaders::sim_neighbours_comp, sizeof(SimPass), kGroup),
      pbf_lambda(c, shaders::sim_pbf_lambda_comp, sizeof(SimPass), kGroup),
      pbf_correct(c, shaders::sim_pbf_correct_comp, sizeof(SimPass), kGroup),
      pbf_sums(c, shaders::sim_pbf_sums_comp, sizeof(SimPass), kGroup),
      pbf_finish(c, shaders::sim_pbf_finish_comp, sizeof(SimPass), kGroup),
      sph_force(c, shaders::sim_sph_force_comp, sizeof(SimPass), kGroup),
      sph_integrate(c, shaders::sim_sph_integrate_comp, sizeof(SimPass), kGroup) {}

std::vector<PassStatistics> GpuSolver::pipeline_statistics(gpu::Context& context) {
  const Pipelines p(context);
  const std::pair<const char*, const gpu::ComputePipeline*> passes[] = {
      {"predict", &p.predict},
      {"reorder", &p.reorder},
      {"neighbours", &p.neighbours},
      {"pbf_lambda", &p.pbf_lambda},
      {"pbf_correct", &p.pbf_correct},
      {"pbf_sums", &p.pbf_sums},
      {"pbf_finish", &p.pbf_finish},
      {"sph_force", &p.sph_force},
      {"sph_integrate", &p.sph_integrate}};
  std::vector<PassStatistics> statistics = GpuNeighbourGrid::pipeline_statistics(context);
  for (const auto& [name, pipeline] : passes) statistics.push_back({name, pipeline->statistics()});
  return statistics;
}

GpuSolver::GpuSolver(SolverKind kind, gpu::Context& context, Scene scene,
                     const SolverParams& params, GpuStepBatch* batch,
                     std::uint64_t memory_budget_bytes)
    : Solver(std::move(scene), params),
      kind_(kind),
      context_(&context),
      own_batch_(batch ? nullptr : std::make_unique<GpuStepBatch>(context)),
      batch_(batch ? batch : own_batch_.get()),
      memory_budget_(
          memory_budget_bytes > 0
              ? memory_budget_bytes
              : static_cast<std::uint64_t>(kUsableMemoryShare *
                                           static_cast<double>(context.info().device_local_bytes))),
      grid_(context, GridGeometry(tank(), fluid().kernel_radius), 0),
      pipelines_(context),
      params_buffer_(context, sizeof(SimParams), gpu::MemoryDomain::device),
      stats_buffer_(context, kStatsSlots * sizeof(std::uint32_t), gpu::MemoryDomain::device),
      in_flight_{InFlight(context), InFlight(context), InFlight(context), InFlight(context)},
      pbf_substeps_(params, fluid().kernel_radius) {
  const PbfConstants pbf = derive_pbf_constants(params, fluid());
  relaxation_epsilon_ = pbf.relaxation_epsilon;
  scorr_scale_ = pbf.scorr_scale;
  inv_w_dq_ = pbf.inv_w_dq;
  load_particles(this->scene().particles);
}

GpuSolver::~GpuSolver() {
  // Only a solver with steps still waiting reaches into its batch: a retired one (submitted
  // before it was retired) may go after the batch has.
  const bool queued = std::any_of(in_flight_.begin(), in_flight_.end(), [](const InFlight& slot) {
    return !slot.harvested && slot.receipt.serial == 0;
  });
  if (queued) batch_->forget(this);
  try {
    for (const InFlight& slot : in_flight_) {
      if (slot.receipt.serial != 0) context_->wait_for(slot.receipt.serial);
    }
  } catch (const gpu::VulkanError&) {
    // A lost device runs nothing any more: the buffers may go.
  }
}

void GpuSolver::submit_queued() const {
  if (batch_->holds(this)) batch_->submit();
}

std::uint64_t GpuSolver::bytes_needed(std::size_t particles) const {
  return particles * bytes_per_particle(kind_, fluid().max_neighbours) +
         GpuNeighbourGrid::bytes_for_cells(grid_.geometry().cell_count());
}

std::size_t GpuSolver::particles_listable() const {
  return kMostListElements / list_elements(fluid().max_neighbours);
}

std::size_t GpuSolver::particles_listed_in_one_allocation() const {
  return context_->info().largest_allocation_bytes /
         list_bytes_per_particle(fluid().max_neighbours);
}

std::size_t GpuSolver::particles_that_fit() const {
  const std::uint64_t grid_bytes = bytes_needed(0);
  const std::uint64_t in_memory =
      memory_budget_ > grid_bytes
          ? (memory_budget_ - grid_bytes) / bytes_per_particle(kind_, fluid().max_neighbours)
          : 0;
  return std::min<std::uint64_t>(
      {in_memory, particles_listable(), particles_listed_in_one_allocation()});
}

GpuSolver::Buffers GpuSolver::allocate(std::size_t capacity) {
  if (capacity > particles_that_fit()) {
    const auto mib = [](std::uint64_t bytes) {
      char text[32];
      std::snprintf(text, sizeof text, "%.1f MiB", static_cast<double>(bytes) / (1 << 20));
      return std::string(text);
    };
    char ratio[16];
    std::snprintf(ratio, sizeof ratio, "%g", static_cast<double>(params().kernel_ratio));
    const std::string lists = "{particles}: " + std::to_string(capacity) +
                              " particles at kernel ratio " + ratio + " need neighbour lists ";
    if (capacity > particles_listable()) {
      throw ParamError(lists + "longer than the GPU solver indexes (2^31 groups of four " +
                       "entries); at most " + std::to_string(particles_listable()) +
                       " at this ratio");
    }
    if (capacity > particles_listed_in_one_allocation()) {
      throw ParamError(
          lists + "(" + std::to_string(list_bytes_per_particle(fluid().max_neighbours)) +
          " bytes a particle) in one buffer, and " + context_->info().name + " allocates at most " +
          mib(context_->info().largest_allocation_bytes) + " in one piece: at most " +
          std::to_string(particles_listed_in_one_allocation()) + " particles at this ratio");
    }
    throw ParamError("{particles}: " + std::to_string(capacity) + " particles need " +
                     mib(bytes_needed(capacity)) + " of GPU memory, over the budget of " +
                     mib(memory_budget_) + " on " + context_->info().name + " (" +
                     std::to_string(particles_that_fit()) + " particles would fit in this tank)");
  }
  const auto bytes = [&](std::uint64_t each) { return std::uint64_t{capacity} * each; };
  const auto device = [&](std::uint64_t each) {
    return gpu::Buffer(*context_, bytes(each), gpu::MemoryDomain::device);
  };
  Buffers b;
  b.position = device(16);
  b.velocity = device(16);
  b.id = device(4);
  b.sorted_position = device(16);
  b.sorted_velocity = device(16);
  b.sorted_id = device(4);
  const bool pbf = kind_ == SolverKind::pbf;
  b.predicted = device(pbf ? 16 : 0);
  b.iterate = device(pbf ? 16 : 0);
  b.iterate_scalar = device(pbf ? 16 : 0);
  b.vorticity = device(pbf ? 16 : 0);
  b.density = device(pbf ? 0 : 8);
  b.acceleration = device(pbf ? 0 : 16);
  b.density_ratio = device(4);
  b.neighbours = device(list_bytes_per_particle(fluid().max_neighbours));
  b.neighbour_count = device(4);
  b.capacity = capacity;
  grid_.reserve(capacity);  // room for more than the particles held is harmless
  return b;
}

GpuSolver::Buffers GpuSolver::allocate_for(std::size_t n) {
  const std::size_t room =
      std::min({2 * buffers_.capacity, static_cast<std::size_t>(params().max_particles),
                particles_that_fit()});
  if (room <= n) return allocate(n);
  try {
    return allocate(room);
  } catch (const gpu::VulkanError& e) {  // the room is not there now; the particles may be
    if (!e.out_of_memory()) throw;
    return allocate(n);
  }
}

void GpuSolver::load_particles(const ParticleSet& particles) {
  upload_particles(particles);
  if (kind_ == SolverKind::pbf) pbf_substeps_.start(particles.position, gravity());
}

void GpuSolver::upload_particles(const ParticleSet& particles) {
  // Steps in flight finish on the old particles (the uploads below wait for them in the queue);
  // their figures no longer describe these particles.
  submit_queued();
  for (InFlight& slot : in_flight_) slot.stale_stats = true;
  const std::size_t n = particles.size();
  // New buffers are taken only once the particles are in them: a failure on the way (no memory
  // for them, or for the upload's staging) leaves the fluid as it was.
  std::optional<Buffers> grown;
  if (n > buffers_.capacity || !buffers_.position) grown = allocate_for(n);
  const Buffers& target = grown ? *grown : buffers_;
  std::vector<glm::vec4> positions(n), velocities(n);
  // Until the first step measures them, the particles show rest density (a scene starts there):
  // a paused fluid's frames, or a new one's first, read these.
  const std::vector<float> at_rest(n, 1.0f);
  float largest_speed2 = 0.0f;
  for (std::size_t i = 0; i < n; ++i) {
    positions[i] = glm::vec4(particles.position[i], 0.0f);
    velocities[i] = glm::vec4(particles.velocity[i], 0.0f);
    largest_speed2 =
        std::max(largest_speed2, glm::dot(particles.velocity[i], particles.velocity[i]));
  }
  const gpu::Upload uploads[] = {
      {target.position, std::as_bytes(std::span<const glm::vec4>(positions))},
      {target.velocity, std::as_bytes(std::span<const glm::vec4>(velocities))},
      {target.id, std::as_bytes(std::span<const std::uint32_t>(particles.id))},
      {target.density_ratio, std::as_bytes(std::span<const float>(at_rest))}};
  gpu::upload_all(*context_, uploads);
  // Steps and frames already submitted may still read the old buffers.
  if (grown) context_->retire(std::exchange(buffers_, std::move(*grown)));
  count_ = n;
  largest_speed_ = std::sqrt(largest_speed2);
  largest_wall_approach_ =
      largest_wall_approach(particles.position, particles.velocity, inner_tank(), wall_reach());
  largest_acceleration_ = 0.0f;
}

ParticleSet GpuSolver::snapshot() const {
  // Queue order puts the copy after every submitted step.
  submit_queued();
  std::vector<glm::vec4> positions(count_), velocities(count_);
  ParticleSet set;
  set.id.resize(count_);
  const gpu::Download downloads[] = {
      {buffers_.position, std::as_writable_bytes(std::span<glm::vec4>(positions))},
      {buffers_.velocity, std::as_writable_bytes(std::span<glm::vec4>(velocities))},
      {buffers_.id, std::as_writable_bytes(std::span<std::uint32_t>(set.id))}};
  gpu::download_all(*context_, downloads);
  set.position.resize(count_);
  set.velocity.resize(count_);
  for (std::size_t i = 0; i < count_; ++i) {
    set.position[i] = glm::vec3(positions[i]);
    set.velocity[i] = glm::vec3(velocities[i]);
  }
  return set;
}

void GpuSolver::append_particles(std::span<const glm::vec3> positions,
                                 std::span<const glm::vec3> velocities, std::uint32_t first_id) {
  ParticleSet set = snapshot();
  for (std::size_t i = 0; i < positions.size(); ++i) {
    set.append(positions[i], velocities[i], first_id + static_cast<std::uint32_t>(i));
  }
  upload_particles(set);
}

std::size_t GpuSolver::erase_particles_in_sphere(glm::vec3 centre, float radius) {
  const ParticleSet all = snapshot();
  ParticleSet kept;
  for (std::size_t i = 0; i < all.size(); ++i) {
    const glm::vec3 d = all.position[i] - centre;
    // NaN positions are kept, to be counted, as the CPU solvers keep them.
    if (!(glm::dot(d, d) <= radius * radius))
      kept.append(all.position[i], all.velocity[i], all.id[i]);
  }
  upload_particles(kept);
  return all.size() - kept.size();
}

void GpuSolver::synchronize() {
  submit_queued();
  for (const InFlight& slot : in_flight_) {
    if (!slot.harvested) context_->wait_for(slot.receipt.serial);
  }
  count_finished_steps();
}

void GpuSolver::count_finished_steps() {
  const std::uint64_t finished = context_->last_finished();
  // Oldest first (the next slot to be used holds the oldest step), so that the newest finished
  // step's figures are the ones kept.
  for (std::size_t k = 0; k < kStepsInFlight; ++k) {
    InFlight& slot = in_flight_[(next_slot_ + k) % kStepsInFlight];
    if (slot.finished(finished)) harvest(slot);
  }
}

void GpuSolver::harvest(InFlight& slot) {
  if (slot.harvested) return;
  slot.harvested = true;
  // The step's share of the batch's timestamps, released once read.
  const std::shared_ptr<gpu::TimestampQueries> timestamps =
      std::exchange(slot.receipt.timestamps, nullptr);
  if (!slot.stale_stats) {
    const auto stats = slot.stats.mapped<std::uint32_t>();
    largest_speed_ = std::sqrt(float_from_bits(stats[kLargestSpeed2]));
    largest_acceleration_ = float_from_bits(stats[kLargestAcceleration]);
    largest_wall_approach_ = float_from_bits(stats[kLargestWallApproach]);
    if (kind_ == SolverKind::pbf) {
      const std::uint64_t sum =
          (std::uint64_t{stats[kCompressionSumHigh]} << 32) | stats[kCompressionSum];
      const double mean =
          slot.particles > 0 ? static_cast<double>(sum) * kCompressionUnit / slot.particles : 0.0;
      pbf_substeps_.observe(slot.stiffness_substep, static_cast<float>(mean));
    }
  }
  // Untimed steps (a device without timestamps) are not counted: a cost of 0 would mean free.
  if (!timestamps || slot.receipt.passes.empty()) return;
  stage_times_.substeps += static_cast<std::uint64_t>(slot.substeps);
  timestamps->fetch();
  for (const GpuStepBatch::Receipt::Timed& pass : slot.receipt.passes) {
    const double ms = timestamps->elapsed_ms(pass.from, pass.to) * pass.share;
    const int index = pass.index;
    switch (static_cast<Stage>(pass.stage)) {
      case Stage::grid:
        stage_times_.grid_ms += ms;
        break;
      case Stage::neighbours:
        stage_times_.neighbours_ms += ms;
        break;
      case Stage::predict:
        stage_times_.predict_ms += ms;
        break;
      case Stage::iteration:
        stage_times_.iteration_ms.resize(std::max<std::size_t>(
            stage_times_.iteration_ms.size(), static_cast<std::size_t>(index) + 1));
        stage_times_.iteration_ms[static_cast<std::size_t>(index)] += ms;
        stage_times_.solve_ms += ms;
        break;
      case Stage::solve:
        stage_times_.solve_ms += ms;
        break;
      case Stage::velocity:
        stage_times_.velocity_ms += ms;
        break;
      case Stage::viscosity:
        stage_times_.viscosity_ms += ms;
        break;
    }
  }
}

void GpuSolver::set_addresses(SimParams& p) const {
  p.position = buffers_.position.address();
  p.velocity = buffers_.velocity.address();
  p.id = buffers_.id.address();
  p.sorted_position = buffers_.sorted_position.address();
  p.sorted_velocity = buffers_.sorted_velocity.address();
  p.sorted_id = buffers_.sorted_id.address();
  p.predicted = buffers_.predicted.address();
  p.iterate = buffers_.iterate.address();
  p.iterate_scalar = buffers_.iterate_scalar.address();
  p.vorticity = buffers_.vorticity.address();
  p.density = buffers_.density.address();
  p.acceleration = buffers_.acceleration.address();
  p.order = grid_.order().address();
  p.cell_start = grid_.cell_start().address();
  p.sorted_cell = grid_.sorted_cell().address();
  p.cell_of = grid_.cell_of().address();
  p.rank = grid_.rank().address();
  p.stats = stats_buffer_.address();
  p.density_ratio = buffers_.density_ratio.address();
  p.neighbours = buffers_.neighbours.address();
  p.neighbour_count = buffers_.neighbour_count.address();
}

SimParams GpuSolver::step_params(int substeps, float stiffness) const {
  const Kernels kernels(fluid().kernel_radius);
  const float radius = fluid().particle_radius();
  const GridGeometry& grid = grid_.geometry();
  SimParams p{};
  set_addresses(p);

  const Box wall_fluid = fluid().wall_fluid_box(tank());
  p.wall_fluid_min = glm::vec4(wall_fluid.min, 0.0f);
  p.wall_fluid_max = glm::vec4(wall_fluid.max, 0.0f);
  p.inner_min = glm::vec4(inner_tank().min, 0.0f);
  p.inner_max = glm::vec4(inner_tank().max, 0.0f);
  p.gravity = glm::vec4(gravity(), 0.0f);
  p.grid_dims = glm::ivec4(grid.dims, 0);
  p.grid_origin = glm::vec4(grid.origin, grid.inv_cell_size);

  p.solver = kind_ == SolverKind::pbf ? kSolverPbf : kSolverSph;
  p.particle_count = static_cast<std::uint32_t>(count_);
  p.collider_count = static_cast<std::uint32_t>(colliders().size());
  p.h = kernels.radius();
  p.h2 = kernels.radius_squared();
  p.poly6 = kernels.poly6_coefficient();
  p.spiky = kernels.spiky_coefficient();
  p.viscosity_laplacian = kernels.viscosity_laplacian_coefficient();
  p.mass = fluid().particle_mass;
  p.rest_density = fluid().rest_density;
  p.inv_rest_density = 1.0f / fluid().rest_density;
  p.rest_volume = fluid().rest_volume();
  p.particle_radius = radius;
  p.relaxation_epsilon = relaxation_epsilon_;
  p.scorr_scale = scorr_scale_;
  p.inv_w_dq = inv_w_dq_;
  p.scorr_exponent = params().scorr_exponent;
  p.vorticity_epsilon = params().vorticity;
  p.xsph = pbf_step_xsph(params(), substeps);
  p.tait_stiffness =
      params().rest_density * params().sound_speed * params().sound_speed / params().tait_exponent;
  p.tait_exponent = params().tait_exponent;
  p.sph_viscosity = params().sph_viscosity;
  p.artificial_viscosity =
      2.0f * params().artificial_viscosity * kernels.radius() * params().sound_speed;
  p.softening = 0.01f * kernels.radius_squared();
  p.substep_travel = params().pbf_travel * kernels.radius();
  p.max_acceleration = params().pbf_max_acceleration;
  p.max_candidates = fluid().max_candidates;
  p.max_neighbours = fluid().max_neighbours;
  p.wall_reach = wall_reach();
  p.stiffness_share = stiffness;
  p.pressed_from = PbfSubsteps::kPressedFrom * params().pbf_density_tolerance;
  p.pressed_span = PbfSubsteps::kPressedSpan * params().pbf_density_tolerance;
  p.max_speed = kMaxSpeed;
  for (std::size_t c = 0; c < colliders().size(); ++c) {
    p.collider_sphere[c] = glm::vec4(colliders()[c].centre, colliders()[c].radius);
    p.collider_velocity[c] = glm::vec4(colliders()[c].velocity, 0.0f);
  }
  return p;
}

int GpuSolver::substeps_for(float seconds) {
  float largest_collider_speed = 0.0f;
  for (const Collider& c : colliders()) {
    largest_collider_speed = std::max(largest_collider_speed, glm::length(c.velocity));
  }
  const float h = fluid().kernel_radius;
  // Steps still running make the figures that many steps older: allow for what gravity adds over
  // them too.
  const int running = steps_running();
  const float g = glm::length(gravity());
  const float speed = largest_speed_ + float(running) * g * seconds;
  if (kind_ == SolverKind::pbf) {
    const float approach = largest_wall_approach_ > 0.0f
                               ? largest_wall_approach_ + float(running) * g * seconds
                               : 0.0f;
    // The density rule hears of a step only once it has finished: near its bound it plans for
    // the compression the running steps may have added unseen, rather than wait for them.
    return pbf_substeps_.count(seconds, speed, largest_collider_speed, approach, g, running);
  }
  const float dt = sph_stable_substep(speed, largest_acceleration_, params(), h);
  if (!std::isfinite(dt) || dt <= 0.0f) return params().max_substeps;
  return static_cast<int>(
      std::clamp(std::ceil(seconds / dt), 1.0f, static_cast<float>(params().max_substeps)));
}

int GpuSolver::steps_running() const {
  const std::uint64_t finished = context_->last_finished();
  int running = 0;
  for (const InFlight& slot : in_flight_) {
    running += !slot.harvested && !slot.finished(finished) ? 1 : 0;
  }
  return running;
}

int GpuSolver::advance(float seconds, int substeps) {
  const float dt = seconds / static_cast<float>(substeps);
  const bool pbf = kind_ == SolverKind::pbf;
  // From the figures and the steps running that planned the step (substeps_for), before the wait
  // below brings newer ones in: those would make it softer than its plan.
  const float stiffness_dt =
      pbf ? pbf_substeps_.stiffness_substep(params().time_step, dt, steps_running()) : dt;
  InFlight& slot = in_flight_[next_slot_];
  if (!slot.harvested) {  // the oldest step, still waiting or running
    if (slot.receipt.serial == 0) batch_->submit();
    context_->wait_for(slot.receipt.serial);
  }
  count_finished_steps();

  Passes passes;
  // First the step's parameters, a clean slate for its figures, and the first substep's grid
  // cleared for its count (each substep's last pass clears it for the next).
  passes.push_back({static_cast<int>(pbf ? Stage::predict : Stage::grid), 0,
                    [this, params_block = step_params(substeps, stiffness_share(dt, stiffness_dt))](
                        VkCommandBuffer c) {
                      vkCmdUpdateBuffer(c, params_buffer_.get(), 0, sizeof(SimParams),
                                        &params_block);
                      vkCmdFillBuffer(c, stats_buffer_.get(), 0, VK_WHOLE_SIZE, 0);
                      grid_.record_clear(c);
                    }});
  for (int s = 0; s < substeps; ++s) {
    const bool last = s + 1 == substeps;
    const SimPass pass{params_buffer_.address(), dt,   static_cast<float>(s + 1) * dt,
                       last ? 1u : 0u,           1.0f, 0};
    if (pbf) {
      append_pbf_substep(passes, pass, last);
    } else {
      append_sph_substep(passes, pass, !last);
    }
  }
  passes.push_back({static_cast<int>(pbf ? Stage::viscosity : Stage::predict), 0,
                    [this, &slot](VkCommandBuffer c) {
                      const VkBufferCopy region{0, 0, kStatsSlots * sizeof(std::uint32_t)};
                      vkCmdCopyBuffer(c, stats_buffer_.get(), slot.stats.get(), 1, &region);
                    }});
  batch_->queue(this, count_, std::move(passes), slot.receipt);
  slot.harvested = false;
  slot.stale_stats = false;
  slot.substeps = substeps;
  slot.stiffness_substep = stiffness_dt;
  slot.particles = count_;
  next_slot_ = (next_slot_ + 1) % kStepsInFlight;
  if (own_batch_) own_batch_->submit();
  return substeps;
}

void GpuSolver::append_pbf_substep(Passes& passes, const SimPass& pass, bool last) const {
  const std::uint32_t n = static_cast<std::uint32_t>(count_);
  const auto add = [&](Stage stage, int index, const gpu::ComputePipeline& pipeline,
                       const SimPass& push) {
    passes.push_back({static_cast<int>(stage), index,
                      [&pipeline, push, n](VkCommandBuffer c) { pipeline.dispatch(c, push, n); }});
  };
  // The prediction counts itself into the grid, and the reorder scatters: the build between is
  // the grid's prefix sum alone.
  add(Stage::predict, 0, pipelines_.predict, pass);
  grid_.append_scan(passes, static_cast<int>(Stage::grid));
  add(Stage::grid, 0, pipelines_.reorder, pass);
  add(Stage::neighbours, 0, pipelines_.neighbours, pass);

  // The listing computes the first iteration's λ. On a substep that is not the step's last, the
  // last correction ends it (writes the state back); it reads no grid, so the next substep's may
  // be cleared beside it.
  const int iterations = params().iterations;
  for (int k = 0; k < iterations; ++k) {
    SimPass correction = pass;
    correction.correction_weight = pbf_correction_weight(params(), k);
    const bool sets_velocity = k + 1 == iterations;
    correction.write_velocity = sets_velocity ? 1 : 0;
    if (k > 0) add(Stage::iteration, k, pipelines_.pbf_lambda, pass);
    passes.push_back({static_cast<int>(Stage::iteration), k,
                      [this, correction, n, clear = sets_velocity && !last](VkCommandBuffer c) {
                        pipelines_.pbf_correct.dispatch(c, correction, n);
                        if (clear) grid_.record_clear(c);
                      }});
  }
  if (!last) return;
  // XSPH, the curl and the compression, once a step at its corrected positions (pbf_step_xsph),
  // then the confinement and the step's end.
  add(Stage::velocity, 0, pipelines_.pbf_sums, pass);
  add(Stage::viscosity, 0, pipelines_.pbf_finish, pass);
}

void GpuSolver::append_sph_substep(Passes& passes, const SimPass& pass,
                                   bool then_clear_grid) const {
  const std::uint32_t n = static_cast<std::uint32_t>(count_);
  const auto add = [&](Stage stage, const gpu::ComputePipeline& pipeline) {
    passes.push_back({static_cast<int>(stage), 0,
                      [&pipeline, pass, n](VkCommandBuffer c) { pipeline.dispatch(c, pass, n); }});
  };
  grid_.append_count(passes, buffers_.position.address(), n, static_cast<int>(Stage::grid));
  grid_.append_scan(passes, static_cast<int>(Stage::grid));
  add(Stage::grid, pipelines_.reorder);
  add(Stage::neighbours, pipelines_.neighbours);  // and the densities
  add(Stage::solve, pipelines_.sph_force);
  // The integration does not read the grid: the next substep's may be cleared beside it.
  passes.push_back(
      {static_cast<int>(Stage::predict), 0, [this, pass, n, then_clear_grid](VkCommandBuffer c) {
         pipelines_.sph_integrate.dispatch(c, pass, n);
         if (then_clear_grid) grid_.record_clear(c);
       }});
}

}  // namespace fluidcast::sim::gpu_solver

namespace fluidcast::sim {

std::unique_ptr<Solver> make_gpu_solver(SolverKind kind, gpu::Context& context, Scene scene,
                                        const SolverParams& params, GpuStepBatch* batch) {
  return std::make_unique<gpu_solver::GpuSolver>(kind, context, std::move(scene), params, batch);
}

std::vector<PassStatistics> gpu_solver_pipeline_statistics(gpu::Context& context) {
  return gpu_solver::GpuSolver::pipeline_statistics(context);
}

}  // namespace fluidcast::sim

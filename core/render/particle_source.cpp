#include "fluidcast/render/particle_source.h"

#include "fluidcast/gpu/transfer.h"
#include "fluidcast/sim/statistics.h"

namespace fluidcast::render {

ParticleView ParticleSource::view_of(const sim::Solver& solver) {
  if (const auto device = solver.device_particles()) {
    ParticleView view;
    view.position = device->position;
    view.velocity = device->velocity;
    view.density_ratio = device->density_ratio;
    view.count = static_cast<std::uint32_t>(solver.particle_count());
    view.radius = solver.fluid().particle_radius();
    return view;
  }
  const sim::ParticleSet particles = solver.snapshot();
  if (!with_densities_) return upload(particles, solver.fluid().particle_radius());
  std::vector<float> ratio = sim::measure_densities(particles, solver.fluid(), solver.tank());
  for (float& r : ratio) r /= solver.fluid().rest_density;
  return upload(particles, solver.fluid().particle_radius(), ratio);
}

ParticleView ParticleSource::upload(const sim::ParticleSet& particles, float radius,
                                    std::span<const float> density_ratio) {
  ParticleView view;
  view.count = static_cast<std::uint32_t>(particles.size());
  view.radius = radius;
  const std::uint64_t bytes = std::uint64_t{view.count} * sizeof(glm::vec4);
  if (!position_ || position_.size() < bytes) {
    // Frames in flight may still read the old buffers.
    context_->retire(std::move(position_));
    context_->retire(std::move(velocity_));
    context_->retire(std::move(density_ratio_));
    position_ = gpu::Buffer(*context_, bytes, gpu::MemoryDomain::device);
    velocity_ = gpu::Buffer(*context_, bytes, gpu::MemoryDomain::device);
    density_ratio_ = gpu::Buffer(*context_, bytes / 4, gpu::MemoryDomain::device);
  }
  std::vector<glm::vec4> data(view.count);
  for (std::size_t i = 0; i < data.size(); ++i) data[i] = glm::vec4(particles.position[i], 0.0f);
  gpu::upload<glm::vec4>(*context_, position_, data);
  for (std::size_t i = 0; i < data.size(); ++i) data[i] = glm::vec4(particles.velocity[i], 0.0f);
  gpu::upload<glm::vec4>(*context_, velocity_, data);
  view.position = position_.address();
  view.velocity = velocity_.address();
  if (density_ratio.size() == particles.size() && !density_ratio.empty()) {
    gpu::upload<float>(*context_, density_ratio_, density_ratio);
    view.density_ratio = density_ratio_.address();
  }
  return view;
}

}  // namespace fluidcast::render

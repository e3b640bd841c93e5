#include "fluidcast/render/particle_source.h"

#include "fluidcast/gpu/transfer.h"

namespace fluidcast::render {

ParticleView ParticleSource::view_of(const sim::Solver& solver) {
  if (const auto device = solver.device_particles()) {
    return {device->position, device->velocity, static_cast<std::uint32_t>(solver.particle_count()),
            solver.fluid().particle_radius()};
  }
  return upload(solver.snapshot(), solver.fluid().particle_radius());
}

ParticleView ParticleSource::upload(const sim::ParticleSet& particles, float radius) {
  ParticleView view;
  view.count = static_cast<std::uint32_t>(particles.size());
  view.radius = radius;
  const std::uint64_t bytes = std::uint64_t{view.count} * sizeof(glm::vec4);
  if (!position_ || position_.size() < bytes) {
    context_->wait_idle();  // frames in flight may still read the old buffers
    position_ = gpu::Buffer(*context_, bytes, gpu::MemoryDomain::device);
    velocity_ = gpu::Buffer(*context_, bytes, gpu::MemoryDomain::device);
  }
  std::vector<glm::vec4> data(view.count);
  for (std::size_t i = 0; i < data.size(); ++i) data[i] = glm::vec4(particles.position[i], 0.0f);
  gpu::upload<glm::vec4>(*context_, position_, data);
  for (std::size_t i = 0; i < data.size(); ++i) data[i] = glm::vec4(particles.velocity[i], 0.0f);
  gpu::upload<glm::vec4>(*context_, velocity_, data);
  view.position = position_.address();
  view.velocity = velocity_.address();
  return view;
}

}  // namespace fluidcast::render

#include "fluidcast/render/particle_source.h"

#include <algorithm>

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

ParticleSource::~ParticleSource() { retire_buffers(); }

void ParticleSource::retire_buffers() {
  for (gpu::Buffer* buffer : {&position_, &velocity_, &density_ratio_}) {
    if (*buffer) context_->retire(std::move(*buffer));
  }
}

ParticleView ParticleSource::upload(const sim::ParticleSet& particles, float radius,
                                    std::span<const float> density_ratio) {
  ParticleView view;
  view.count = static_cast<std::uint32_t>(particles.size());
  view.radius = radius;
  // Frames already submitted may still read the last particles: those buffers are retired after
  // them, and these particles go to buffers of their own in host-visible memory, written in place.
  // A copy on the queue would make the worker wait for everything queued before it, every
  // session's every frame.
  retire_buffers();
  const std::uint64_t bytes = std::uint64_t{view.count} * sizeof(glm::vec4);
  position_ = gpu::Buffer(*context_, bytes, gpu::MemoryDomain::upload);
  velocity_ = gpu::Buffer(*context_, bytes, gpu::MemoryDomain::upload);
  const std::span<glm::vec4> position = position_.mapped<glm::vec4>();
  const std::span<glm::vec4> velocity = velocity_.mapped<glm::vec4>();
  for (std::size_t i = 0; i < view.count; ++i) {
    position[i] = glm::vec4(particles.position[i], 0.0f);
    velocity[i] = glm::vec4(particles.velocity[i], 0.0f);
  }
  view.position = position_.address();
  view.velocity = velocity_.address();
  if (density_ratio.size() == particles.size() && !density_ratio.empty()) {
    density_ratio_ = gpu::Buffer(*context_, density_ratio.size_bytes(), gpu::MemoryDomain::upload);
    std::copy(density_ratio.begin(), density_ratio.end(), density_ratio_.mapped<float>().begin());
    view.density_ratio = density_ratio_.address();
  }
  return view;
}

}  // namespace fluidcast::render

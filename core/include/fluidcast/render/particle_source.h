// The particles of any solver as the renderer reads them: a GPU solver's buffers in place (it must
// run on the renderer's context), a CPU solver's copied up each frame (the client's local mode).
#pragma once

#include "fluidcast/gpu/buffer.h"
#include "fluidcast/render/frame_renderer.h"
#include "fluidcast/sim/solver.h"

namespace fluidcast::render {

class ParticleSource {
 public:
  // with_densities: a CPU solver's particles come with ρ/ρ0 (for points coloured by density).
  explicit ParticleSource(gpu::Context& context, bool with_densities = false)
      : context_(&context), with_densities_(with_densities) {}
  ~ParticleSource();
  ParticleSource(const ParticleSource&) = delete;
  ParticleSource& operator=(const ParticleSource&) = delete;

  ParticleView view_of(const sim::Solver& solver);
  // Copies particles up (what view_of does for a CPU solver, with its densities ρ/ρ0 measured
  // by sim::measure_densities, walls included, as the GPU solver's are).
  ParticleView upload(const sim::ParticleSet& particles, float radius,
                      std::span<const float> density_ratio = {});

 private:
  // Retired after the frames submitted so far, which may read them.
  void retire_buffers();

  gpu::Context* context_;
  bool with_densities_;
  gpu::Buffer position_, velocity_, density_ratio_;  // a CPU solver's newest particles
};

}  // namespace fluidcast::render

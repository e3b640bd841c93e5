// The particles of any solver as the renderer reads them: a GPU solver's buffers in place (it must
// run on the renderer's context), a CPU solver's copied up each frame (the client's local mode).
#pragma once

#include "fluidcast/gpu/buffer.h"
#include "fluidcast/render/frame_renderer.h"
#include "fluidcast/sim/solver.h"

namespace fluidcast::render {

class ParticleSource {
 public:
  explicit ParticleSource(gpu::Context& context) : context_(&context) {}

  ParticleView view_of(const sim::Solver& solver);
  // Copies particles up (what view_of does for a CPU solver).
  ParticleView upload(const sim::ParticleSet& particles, float radius);

 private:
  gpu::Context* context_;
  gpu::Buffer position_, velocity_;  // for CPU solvers
};

}  // namespace fluidcast::render

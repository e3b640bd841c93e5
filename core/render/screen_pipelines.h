// The compute pipelines every FrameRenderer on a device runs alike (they depend on neither the
// frame's size nor what it shows), compiled once and shared: a new viewer or a resize makes a
// renderer, and on a CPU device each compute pipeline is a compilation (lavapipe: a few ms each).
#pragma once

#include <memory>

#include "fluidcast/gpu/compute_pipeline.h"

namespace fluidcast::render {

struct ScreenPipelines {
  explicit ScreenPipelines(gpu::Context& context);

  // The device's set: made for the first renderer that asks, kept while any renderer holds it
  // (renderers go before their context, and so does the set).
  static std::shared_ptr<const ScreenPipelines> shared(gpu::Context& context);

  gpu::ComputePipeline splat, splat_large, splat_resolve, smooth, shade, yuv420;
};

}  // namespace fluidcast::render

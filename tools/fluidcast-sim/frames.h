// fluidcast-sim --render: draws the fluid offscreen and writes each frame as PNG.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>

#include "fluidcast/render/frame_renderer.h"
#include "fluidcast/render/particle_source.h"
#include "options.h"
#include "video.h"

namespace fluidcast::tools {

class FrameWriter {
 public:
  // The camera looks at the tank's centre; without --camera, from 30° yaw, 20° pitch and far
  // enough to see the whole tank.
  FrameWriter(const SimOptions& options, gpu::Context& context, const sim::Solver& solver);

  // Renders the solver's particles now: into frame_NNNNNN.png (numbered from 0) with --render,
  // into the video with --video.
  void write(const sim::Solver& solver);
  // Writes the frames still rendering and closes the video; throws std::runtime_error when
  // ffmpeg failed.
  void finish();
  std::uint64_t frames() const { return frames_; }

 private:
  void emit(const codec::ImageRgba& image);

  std::filesystem::path folder_;  // empty: no PNG files
  std::optional<VideoPipe> video_;
  render::ParticleSource source_;  // before the renderer, which waits for its frames first
  render::FrameRenderer renderer_;
  render::OrbitCamera camera_;
  render::RendererKind kind_;
  std::uint64_t frames_ = 0;
};

}  // namespace fluidcast::tools

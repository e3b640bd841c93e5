#include "frames.h"

#include <cstdio>

#include "fluidcast/codec/png.h"

namespace fluidcast::tools {

FrameWriter::FrameWriter(const SimOptions& options, gpu::Context& context,
                         const sim::Solver& solver)
    : folder_(options.render_dir),
      renderer_(context, static_cast<std::uint32_t>(options.width),
                static_cast<std::uint32_t>(options.height)),
      source_(context),
      kind_(render::parse_renderer(options.renderer)) {
  const sim::Box& tank = solver.tank();
  camera_.target = 0.5f * (tank.min + tank.max);
  camera_.distance = 1.2f * glm::length(tank.size());
  if (options.camera) {
    camera_.yaw_degrees = (*options.camera)[0];
    camera_.pitch_degrees = (*options.camera)[1];
    camera_.distance = (*options.camera)[2];
  }
  camera_.validate();
  std::filesystem::create_directories(folder_);
}

void FrameWriter::write(const sim::Solver& solver) {
  const codec::ImageRgba image =
      renderer_.render(kind_, source_.view_of(solver), solver.tank(), camera_);
  char name[32];
  std::snprintf(name, sizeof(name), "frame_%06llu.png", static_cast<unsigned long long>(frames_));
  codec::write_png(folder_ / name, image);
  ++frames_;
}

}  // namespace fluidcast::tools

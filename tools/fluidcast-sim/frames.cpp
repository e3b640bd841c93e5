#include "frames.h"

#include <cstdio>
#include <variant>

#include "fluidcast/codec/png.h"

namespace fluidcast::tools {

FrameWriter::FrameWriter(const SimOptions& options, gpu::Context& context,
                         const sim::Solver& solver)
    : folder_(options.render_dir),
      source_(context, options.colour_by_density),
      renderer_(context, static_cast<std::uint32_t>(options.width),
                static_cast<std::uint32_t>(options.height)),
      kind_(render::parse_renderer(options.renderer)) {
  if (options.colour_by_density) {
    renderer_.points.colour_by = render::PointsStyle::ColourBy::density;
  }
  renderer_.ssfr.depth_falloff_radii = options.ssfr_depth_falloff;
  renderer_.ssfr.anisotropic = options.ssfr_anisotropic;
  renderer_.ssfr.spray_neighbours = options.ssfr_spray_neighbours;
  renderer_.ssfr.filter = options.narrow_range_filter ? render::SsfrStyle::DepthFilter::narrow_range
                                                      : render::SsfrStyle::DepthFilter::bilateral;
  const sim::Box& tank = solver.tank();
  camera_.target = 0.5f * (tank.min + tank.max);
  camera_.distance = 1.2f * glm::length(tank.size());
  if (options.camera) {
    camera_.yaw_degrees = (*options.camera)[0];
    camera_.pitch_degrees = (*options.camera)[1];
    camera_.distance = (*options.camera)[2];
  }
  camera_.validate();
  if (!folder_.empty()) std::filesystem::create_directories(folder_);
  if (!options.video_path.empty()) {
    const double frames_per_second =
        1.0 / (static_cast<double>(options.render_every) * options.solver.time_step);
    video_.emplace(options.video_path, options.width, options.height, frames_per_second);
  }
}

void FrameWriter::finish() {
  while (renderer_.frames_pending() > 0) emit(std::get<codec::ImageRgba>(renderer_.take_oldest()));
  if (video_) video_->finish();
  video_.reset();
}

// The frame renders while the solver takes its next steps; the one before it is written now.
void FrameWriter::write(const sim::Solver& solver) {
  renderer_.submit(kind_, source_.view_of(solver), solver.tank(), camera_);
  while (renderer_.frames_pending() >= render::FrameRenderer::kFramesInFlight) {
    emit(std::get<codec::ImageRgba>(renderer_.take_oldest()));
  }
}

void FrameWriter::emit(const codec::ImageRgba& image) {
  if (!folder_.empty()) {
    char name[32];
    std::snprintf(name, sizeof(name), "frame_%06llu.png", static_cast<unsigned long long>(frames_));
    codec::write_png(folder_ / name, image);
  }
  if (video_) video_->write(image);
  ++frames_;
}

}  // namespace fluidcast::tools

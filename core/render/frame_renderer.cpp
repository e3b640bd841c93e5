#include "fluidcast/render/frame_renderer.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>

#include "anisotropy.h"
#include "fluid_target.h"
#include "fluidcast/gpu/transfer.h"
#include "fluidcast_shaders/fluidcast_render.h"
#include "frame_params.h"
#include "graphics_pipeline.h"
#include "marching_cubes.h"
#include "screen_pipelines.h"

namespace fluidcast::render {
namespace {

using gpu::memory_barrier;

constexpr VkPipelineStageFlags kDrawStages =
    VK_PIPELINE_STAGE_VERTEX_SHADER_BIT | VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT;
constexpr VkPipelineStageFlags kCompute = VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT;
constexpr VkPipelineStageFlags kTransfer = VK_PIPELINE_STAGE_TRANSFER_BIT;
constexpr VkAccessFlags kShaderAccess = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT;
constexpr VkPipelineStageFlags kIndirect = VK_PIPELINE_STAGE_DRAW_INDIRECT_BIT;
constexpr std::uint32_t kInfinityBits = 0x7f800000;  // +inf, a float: no surface at the pixel
// Particles queued for a workgroup each (particle_splat_large.comp), at most: within every
// device's limit on workgroups in x. Beyond it, the particle's own invocation casts them all.
constexpr std::uint32_t kLargeSplatCapacity = 65535;

}  // namespace

double RenderTimes::drawing_ms() const {
  double sum = 0.0;
  for (const auto& [name, pass] : kRenderPasses) {
    if (pass != &RenderTimes::readback_ms) sum += this->*pass;
  }
  return sum;
}

const std::vector<std::string_view>& renderer_names() {
  static const std::vector<std::string_view> names = {"points", "ssfr", "mc", "auto"};
  return names;
}

std::string_view renderer_name(RendererKind kind) {
  return renderer_names()[static_cast<std::size_t>(kind)];
}

RendererKind parse_renderer(std::string_view name) {
  if (name == "points") return RendererKind::points;
  if (name == "ssfr") return RendererKind::ssfr;
  if (name == "mc") return RendererKind::mc;
  if (name == "auto") return RendererKind::automatic;
  throw std::invalid_argument("renderer '" + std::string(name) +
                              "' is not one of: points, ssfr, mc, auto");
}

RendererKind resolve(RendererKind kind, std::uint32_t particles) {
  if (kind != RendererKind::automatic) return kind;
  return particles < kMarchingCubesBelow ? RendererKind::mc : RendererKind::ssfr;
}

FrameRenderer::FrameRenderer(gpu::Context& context, std::uint32_t width, std::uint32_t height)
    : context_(&context),
      target_(context, width, height),
      background_(std::make_unique<GraphicsPipeline>(
          context, target_.render_pass(), shaders::render_background_vert,
          shaders::render_background_frag, PipelineOptions{})),
      pipelines_(ScreenPipelines::shared(context)),
      frame_params_(context, sizeof(FrameParams), gpu::MemoryDomain::device),
      splat_queue_(context, sizeof(std::uint32_t) * (4 + std::uint64_t{kLargeSplatCapacity}),
                   gpu::MemoryDomain::device) {
  // On a CPU device the ellipsoids' neighbour loop costs more than the rest of a frame (lavapipe,
  // 2 cores: ~1.6 µs a particle), and a frame is one indivisible piece of the GPU's time.
  ssfr.anisotropic = context.info().hardware();
  if (FluidTarget::supported(context)) {
    fluid_target_ = std::make_unique<FluidTarget>(context, target_);
    // No depth test: the mesh closes just outside the tank's walls, behind the scene, and the
    // thickness needs every face.
    mc_surface_ = std::make_unique<GraphicsPipeline>(
        context, fluid_target_->render_pass(), shaders::render_mc_vert,
        shaders::render_mc_surface_frag, PipelineOptions{{Blend::min, Blend::add, Blend::add}});
  }
  const std::uint64_t per_pixel = std::uint64_t{width} * height * 4;
  for (gpu::Buffer* buffer : {&depth_, &depth_scratch_, &thickness_, &spray_, &scene_, &image_}) {
    *buffer = gpu::Buffer(context, per_pixel, gpu::MemoryDomain::device);
  }
  planes_ = gpu::Buffer(context, frame_bytes(FrameFormat::yuv420), gpu::MemoryDomain::device);
  slots_.reserve(kFramesInFlight);
  // Each read-back slot holds the frame in either format and, after it, the probed surface
  // distance.
  const std::uint64_t largest =
      std::max(frame_bytes(FrameFormat::rgba), frame_bytes(FrameFormat::yuv420));
  for (std::size_t k = 0; k < kFramesInFlight; ++k) {
    slots_.emplace_back(context, largest + sizeof(float));
  }
}

std::optional<std::string> FrameRenderer::mc_unsupported(const gpu::Context& context) {
  if (FluidTarget::supported(context)) return std::nullopt;
  return "renderer mc: the device " + context.info().name +
         " cannot blend 32-bit float attachments each its own way (R32_SFLOAT "
         "COLOR_ATTACHMENT_BLEND, independentBlend)";
}

RendererKind FrameRenderer::drawable(RendererKind kind, std::uint32_t particles) const {
  const RendererKind resolved = resolve(kind, particles);
  return resolved == RendererKind::mc && !fluid_target_ ? RendererKind::ssfr : resolved;
}

std::uint64_t FrameRenderer::frame_bytes(FrameFormat frame_format) const {
  const int width = static_cast<int>(target_.width()), height = static_cast<int>(target_.height());
  return frame_format == FrameFormat::rgba ? std::uint64_t{4} * std::uint64_t(width) * height
                                           : codec::ImageYuv420::size_for(width, height);
}

FrameRenderer::Slot::Slot(gpu::Context& context, std::uint64_t bytes)
    : readback(context, bytes, gpu::MemoryDomain::readback),
      timestamps(context, 8),
      commands(context) {}

// The slots, declared after what their frames use, wait for their frames before it goes.
FrameRenderer::~FrameRenderer() = default;

std::size_t FrameRenderer::frames_pending() const {
  std::size_t in_flight = 0;
  for (const Slot& slot : slots_) in_flight += slot.in_flight ? 1 : 0;
  return kept_.size() + in_flight;
}

codec::Image FrameRenderer::collect(Slot& slot) {
  slot.commands.wait();
  slot.in_flight = false;
  slot.timestamps.fetch();
  RenderTimes times;
  for (const auto& [pass, to] : slot.timed) times.*pass = slot.timestamps.elapsed_ms(to - 1, to);
  last_times_ = times;
  const int width = static_cast<int>(target_.width()), height = static_cast<int>(target_.height());
  const std::span<const std::uint8_t> bytes = slot.readback.mapped<std::uint8_t>();
  const std::uint64_t image_bytes = frame_bytes(slot.format);
  codec::Image image;
  if (slot.format == FrameFormat::rgba) {
    codec::ImageRgba rgba(width, height);
    std::memcpy(rgba.pixels.data(), bytes.data(), image_bytes);
    image = std::move(rgba);
  } else {
    codec::ImageYuv420 planes(width, height);
    std::memcpy(planes.bytes.data(), bytes.data(), image_bytes);
    image = std::move(planes);
  }
  last_probe_hit_.reset();
  if (slot.probe) {
    float distance = 0.0f;  // along the view axis, as the surface passes store it
    std::memcpy(&distance, bytes.data() + image_bytes, sizeof distance);
    if (std::isfinite(distance)) {
      last_probe_hit_ = unproject(slot.view, slot.projection, *slot.probe, distance);
    }
  }
  return image;
}

std::uint64_t FrameRenderer::submit(RendererKind requested, const ParticleView& particles,
                                    const sim::Box& tank, const OrbitCamera& camera) {
  camera.validate();
  const RendererKind kind =
      requested == RendererKind::automatic ? drawable(requested, particles.count) : requested;
  if (points.colour_by == PointsStyle::ColourBy::density &&
      ((particles.count > 0 && particles.density_ratio == 0) || !(points.density_span > 0.0f))) {
    throw std::invalid_argument(
        "points coloured by density: these particles come without densities, or the span is "
        "not positive");
  }
  if (!(ssfr.smoothing_radii > 0.0f && ssfr.depth_falloff_radii > 0.0f &&
        mc.smoothing_radii > 0.0f && ssfr.smoothing_passes >= 0 && mc.smoothing_passes >= 0)) {
    throw std::invalid_argument(
        "renderer: smoothing radius and depth falloff must be positive, passes not negative");
  }
  if (!(ssfr.max_stretch >= 1.0f && ssfr.max_stretch <= 16.0f && ssfr.centre_smoothing >= 0.0f &&
        ssfr.centre_smoothing <= 1.0f && ssfr.spray_neighbours >= 0 &&
        ssfr.spray_neighbours <= 32)) {
    throw std::invalid_argument(
        "renderer: anisotropy's stretch must lie in 1 to 16, its centre smoothing in 0 to 1, its "
        "spray neighbours in 0 to 32");
  }
  if (kind == RendererKind::mc && !fluid_target_) {
    throw std::invalid_argument(*mc_unsupported(*context_) + "; use ssfr or points");
  }
  if (kind == RendererKind::mc) {
    const int resolution =
        mc.resolution != 0 ? mc.resolution : MarchingCubes::resolution_for(tank, particles.radius);
    if (!marching_cubes_ || !marching_cubes_->fits(tank, resolution, particles.radius)) {
      if (marching_cubes_) context_->retire(std::move(marching_cubes_));  // frames may read it
      marching_cubes_ =
          std::make_unique<MarchingCubes>(*context_, tank, resolution, particles.radius);
    }
  }
  Slot& slot = slots_[next_frame_ % slots_.size()];
  if (slot.in_flight) {
    kept_.push_back(collect(slot));
    while (kept_.size() > kFramesInFlight) {
      kept_.pop_front();
      ++dropped_;
    }
  }
  if (probe && !(glm::all(glm::greaterThanEqual(*probe, glm::vec2(0.0f))) &&
                 glm::all(glm::lessThanEqual(*probe, glm::vec2(1.0f))))) {
    throw std::invalid_argument("renderer: the probe must lie in the frame, 0 to 1 each way");
  }
  slot.probe = kind == RendererKind::points ? std::nullopt : probe;
  slot.format = format;
  try {
    record(slot.commands.begin(), kind, particles, tank, camera, slot);
    slot.commands.submit();
  } catch (...) {
    scene_drawn_for_.reset();  // the scene this frame was to draw may never have been drawn
    // Nor its first frame's filling of the tables: a new one, whose first frame does it.
    if (marching_cubes_) context_->retire(std::move(marching_cubes_));
    throw;
  }
  slot.in_flight = true;
  slot.frame = next_frame_;
  return next_frame_++;
}

FrameRenderer::Slot* FrameRenderer::oldest_in_flight() {
  Slot* oldest = nullptr;
  for (Slot& slot : slots_) {
    if (slot.in_flight && (!oldest || slot.frame < oldest->frame)) oldest = &slot;
  }
  return oldest;
}

bool FrameRenderer::oldest_finished() {
  if (!kept_.empty()) return true;
  const Slot* oldest = oldest_in_flight();
  return oldest && !oldest->commands.busy();
}

codec::Image FrameRenderer::take_oldest() {
  if (!kept_.empty()) {
    // Swapped out rather than moved: GCC 12 takes the variant's move for a read of the
    // uninitialised (-Wmaybe-uninitialized).
    codec::Image image;
    image.swap(kept_.front());
    kept_.pop_front();
    return image;
  }
  Slot* oldest = oldest_in_flight();
  if (!oldest) throw std::logic_error("frame renderer: no frame was submitted");
  return collect(*oldest);
}

std::vector<float> FrameRenderer::surface_distances() const {
  // Queue order puts the copy after the frames submitted.
  return gpu::download<float>(*context_, depth_, std::size_t{target_.width()} * target_.height());
}

codec::Image FrameRenderer::render(RendererKind kind, const ParticleView& particles,
                                   const sim::Box& tank, const OrbitCamera& camera) {
  while (frames_pending() > 0) take_oldest();
  submit(kind, particles, tank, camera);
  return take_oldest();
}

FrameParams FrameRenderer::frame_params(RendererKind kind, const ParticleView& particles,
                                        const sim::Box& tank, const OrbitCamera& camera) const {
  const std::uint32_t width = target_.width(), height = target_.height();
  FrameParams frame{};
  frame.view = camera.view();
  frame.projection = camera.projection(float(width) / float(height));
  frame.inverse_view = glm::inverse(frame.view);
  frame.light_direction = frame.view * glm::vec4(glm::normalize(glm::vec3(0.3f, 1.0f, 0.5f)), 0.0f);
  frame.slow_colour = glm::vec4(points.slow_colour, 1.0f);
  frame.fast_colour = glm::vec4(points.fast_colour, 1.0f);
  frame.tank_min = glm::vec4(tank.min, 0.0f);
  frame.tank_max = glm::vec4(tank.max, 0.0f);
  frame.absorption = glm::vec4(ssfr.absorption, 0.0f);
  frame.particle_radius = particles.radius;
  frame.full_speed = points.full_speed;
  frame.smoothing_radius =
      (kind == RendererKind::mc ? mc.smoothing_radii : ssfr.smoothing_radii) * particles.radius;
  frame.depth_falloff = ssfr.depth_falloff_radii * particles.radius;
  frame.width = width;
  frame.height = height;
  frame.colour_by_density = points.colour_by == PointsStyle::ColourBy::density ? 1u : 0u;
  frame.density_span = points.density_span;
  return frame;
}

void FrameRenderer::Slot::mark(VkCommandBuffer recording, double RenderTimes::*pass) {
  timed.emplace_back(pass, timestamps.mark(recording));
}

void FrameRenderer::record(VkCommandBuffer commands, RendererKind kind,
                           const ParticleView& particles, const sim::Box& tank,
                           const OrbitCamera& camera, Slot& slot) {
  const FrameParams frame = frame_params(kind, particles, tank, camera);
  slot.view = frame.view;
  slot.projection = frame.projection;
  // The solver's writes (compute, transfers) before this frame reads the particles in place; and
  // the previous frame's reads of what frames share (the per-pixel buffers, the anisotropy's
  // grid and ellipsoids, the particle passes' queue) before this one writes them; and the previous
  // frame's writes of those before this one's writes (write after write needs the memory made
  // available, not only the order).
  memory_barrier(commands, kCompute | kTransfer | kDrawStages | kIndirect,
                 VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT,
                 kDrawStages | kTransfer | kCompute, kShaderAccess | VK_ACCESS_TRANSFER_WRITE_BIT);
  vkCmdUpdateBuffer(commands, frame_params_.get(), 0, sizeof(frame), &frame);
  memory_barrier(commands, kTransfer, VK_ACCESS_TRANSFER_WRITE_BIT, kDrawStages | kCompute,
                 kShaderAccess);

  slot.timestamps.reset(commands);
  slot.timed.clear();
  slot.timestamps.mark(commands);
  const ParticleShapes shapes = record_shapes(commands, kind, particles, tank, slot);
  record_scene(commands, SceneKey{frame.view, frame.projection, tank.min, tank.max}, slot);
  // Points into the finished frame; SSFR and MC into the per-pixel surface buffers that the
  // filter and the shading read (SSFR in compute, MC through FluidTarget's attachments).
  if (kind == RendererKind::points) {
    record_points(commands, shapes, particles.count);
  } else if (kind == RendererKind::ssfr) {
    record_ssfr_particles(commands, shapes, particles.count);
  } else {
    fluid_target_->begin(commands);
    if (particles.count > 0) {
      mc_surface_->draw_indirect(commands, {frame_params_.address(), marching_cubes_->vertices()},
                                 marching_cubes_->draw_buffer());
    }
    fluid_target_->end(commands);
    fluid_target_->record_read(commands, depth_, thickness_, spray_);
  }
  slot.mark(commands, &RenderTimes::particles_ms);
  if (kind != RendererKind::points) record_fluid_screen(commands, kind, slot);
  record_read_back(commands, slot);
  slot.mark(commands, &RenderTimes::readback_ms);
  // A GPU solver's next step writes what this frame read (write after read); and the host reads
  // the copy.
  memory_barrier(commands, kDrawStages | kCompute, 0, kCompute | kTransfer, 0);
  memory_barrier(commands, kTransfer, VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_HOST_BIT,
                 VK_ACCESS_HOST_READ_BIT);
}

FrameRenderer::ParticleShapes FrameRenderer::record_shapes(VkCommandBuffer commands,
                                                           RendererKind kind,
                                                           const ParticleView& particles,
                                                           const sim::Box& tank, Slot& slot) {
  ParticleShapes shapes{particles.position, particles.velocity, particles.density_ratio, 0, false};
  if (particles.count == 0) return shapes;
  if (kind == RendererKind::mc) {
    marching_cubes_->record_field(commands, particles, mc.threshold);
    slot.mark(commands, &RenderTimes::mc_field_ms);
    marching_cubes_->record_triangles(commands, particles, mc.threshold);
    slot.mark(commands, &RenderTimes::mc_triangles_ms);
  } else if (kind == RendererKind::ssfr && ssfr.anisotropic) {
    if (!anisotropy_) anisotropy_ = std::make_unique<Anisotropy>(*context_);
    anisotropy_->record(commands, particles, tank, ssfr);
    slot.mark(commands, &RenderTimes::anisotropy_ms);
    shapes.position = anisotropy_->centres().address();
    shapes.shape = anisotropy_->shapes().address();
    shapes.ellipsoids = true;
  }
  return shapes;
}

void FrameRenderer::record_scene(VkCommandBuffer commands, const SceneKey& scene, Slot& slot) {
  // The scene depends on the camera and the tank only: while they stay, frames keep its colour
  // in scene_ from the frame that drew it.
  if (scene_drawn_for_ != scene) {
    const float clear[4] = {0.0f, 0.0f, 0.0f, 1.0f};
    target_.begin(commands, clear);
    background_->draw(commands, {frame_params_.address(), 0}, 3);
    target_.end(commands);
    VkBufferImageCopy region{};
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.imageExtent = {target_.width(), target_.height(), 1};
    vkCmdCopyImageToBuffer(commands, target_.colour().get(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                           scene_.get(), 1, &region);
    memory_barrier(commands, kTransfer, VK_ACCESS_TRANSFER_WRITE_BIT, kTransfer | kCompute,
                   VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_SHADER_READ_BIT);
    scene_drawn_for_ = scene;
  }
  slot.mark(commands, &RenderTimes::scene_ms);
}

SplatConstants FrameRenderer::splat_constants(const ParticleShapes& shapes, std::uint32_t particles,
                                              SplatMode mode) const {
  return SplatConstants{frame_params_.address(),
                        shapes.position,
                        shapes.velocity,
                        shapes.density_ratio,
                        shapes.shape,
                        depth_.address(),
                        thickness_.address(),
                        spray_.address(),
                        image_.address(),
                        splat_queue_.address(),
                        particles,
                        shapes.ellipsoids ? 1u : 0u,
                        kLargeSplatCapacity,
                        static_cast<std::uint32_t>(mode)};
}

void FrameRenderer::record_particle_pass(VkCommandBuffer commands,
                                         const SplatConstants& splat) const {
  const std::uint32_t empty_queue[4] = {0, 1, 1, 0};  // no workgroups (x, y, z), none queued
  vkCmdUpdateBuffer(commands, splat_queue_.get(), 0, sizeof empty_queue, empty_queue);
  memory_barrier(commands, kTransfer, VK_ACCESS_TRANSFER_WRITE_BIT, kCompute, kShaderAccess);
  pipelines_->splat.dispatch(commands, splat, splat.particle_count);
  memory_barrier(commands, kCompute, VK_ACCESS_SHADER_WRITE_BIT, kCompute | kIndirect,
                 kShaderAccess | VK_ACCESS_INDIRECT_COMMAND_READ_BIT);
  pipelines_->splat_large.dispatch_indirect(commands, splat, splat_queue_.get(), 0);
  // Its writes before what reads them; its reads of the queue before the next pass resets it.
  memory_barrier(commands, kCompute | kIndirect, VK_ACCESS_SHADER_WRITE_BIT, kCompute | kTransfer,
                 kShaderAccess | VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_TRANSFER_WRITE_BIT);
}

void FrameRenderer::record_ssfr_particles(VkCommandBuffer commands, const ParticleShapes& shapes,
                                          std::uint32_t particles) {
  const std::uint64_t pixel_bytes = std::uint64_t{target_.width()} * target_.height() * 4;
  vkCmdFillBuffer(commands, depth_.get(), 0, pixel_bytes, kInfinityBits);
  vkCmdFillBuffer(commands, thickness_.get(), 0, pixel_bytes, 0);
  vkCmdFillBuffer(commands, spray_.get(), 0, pixel_bytes, 0);
  const SplatConstants splat = splat_constants(shapes, particles, SplatMode::ssfr);
  record_particle_pass(commands, splat);
  pipelines_->splat_resolve.dispatch(commands, splat, pixel_bytes / 4);
}

void FrameRenderer::record_points(VkCommandBuffer commands, const ParticleShapes& shapes,
                                  std::uint32_t particles) {
  const std::uint64_t pixel_bytes = std::uint64_t{target_.width()} * target_.height() * 4;
  vkCmdFillBuffer(commands, depth_.get(), 0, pixel_bytes, kInfinityBits);
  const VkBufferCopy scene{0, 0, pixel_bytes};
  vkCmdCopyBuffer(commands, scene_.get(), image_.get(), 1, &scene);
  record_particle_pass(commands, splat_constants(shapes, particles, SplatMode::points_distance));
  record_particle_pass(commands, splat_constants(shapes, particles, SplatMode::points_colour));
}

void FrameRenderer::record_fluid_screen(VkCommandBuffer commands, RendererKind kind, Slot& slot) {
  const std::uint32_t width = target_.width(), height = target_.height();
  memory_barrier(commands, kTransfer | kCompute,
                 VK_ACCESS_TRANSFER_WRITE_BIT | VK_ACCESS_SHADER_WRITE_BIT, kCompute,
                 kShaderAccess);
  const std::uint64_t pixels = std::uint64_t{width} * height;
  ScreenConstants screen{frame_params_.address(),
                         depth_.address(),
                         depth_scratch_.address(),
                         thickness_.address(),
                         spray_.address(),
                         scene_.address(),
                         image_.address(),
                         0,
                         ssfr.filter == SsfrStyle::DepthFilter::narrow_range ? 1u : 0u};
  // The separable filter, x then y, applied smoothing_passes times; ends in depth_.
  const int smoothing_passes =
      kind == RendererKind::mc ? mc.smoothing_passes : ssfr.smoothing_passes;
  for (int pass = 0; pass < 2 * smoothing_passes; ++pass) {
    screen.axis = static_cast<std::uint32_t>(pass % 2);
    screen.depth_in = pass % 2 == 0 ? depth_.address() : depth_scratch_.address();
    screen.depth_out = pass % 2 == 0 ? depth_scratch_.address() : depth_.address();
    pipelines_->smooth.dispatch(commands, screen, pixels);
    memory_barrier(commands, kCompute, VK_ACCESS_SHADER_WRITE_BIT, kCompute, kShaderAccess);
  }
  slot.mark(commands, &RenderTimes::smoothing_ms);
  screen.depth_in = depth_.address();
  pipelines_->shade.dispatch(commands, screen, pixels);
  slot.mark(commands, &RenderTimes::shading_ms);
}

void FrameRenderer::record_read_back(VkCommandBuffer commands, const Slot& slot) {
  const std::uint32_t width = target_.width(), height = target_.height();
  memory_barrier(commands, kCompute | kTransfer,
                 VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT, kCompute | kTransfer,
                 VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_TRANSFER_READ_BIT);
  if (slot.format == FrameFormat::yuv420) {
    record_yuv420_read_back(commands, slot);
  } else {
    const VkBufferCopy copy{0, 0, std::uint64_t{width} * height * 4};
    vkCmdCopyBuffer(commands, image_.get(), slot.readback.get(), 1, &copy);
  }
  if (slot.probe) {  // the surface's distance under the finger, after the frame
    const auto x = std::min(width - 1, static_cast<std::uint32_t>(slot.probe->x * width));
    const auto y = std::min(height - 1, static_cast<std::uint32_t>(slot.probe->y * height));
    const VkBufferCopy surface{(std::uint64_t{y} * width + x) * 4, frame_bytes(slot.format), 4};
    vkCmdCopyBuffer(commands, depth_.get(), slot.readback.get(), 1, &surface);
  }
}

void FrameRenderer::record_yuv420_read_back(VkCommandBuffer commands, const Slot& slot) {
  codec::ImageYuv420 shape;
  shape.width = static_cast<int>(target_.width());
  shape.height = static_cast<int>(target_.height());
  const YuvConstants convert{image_.address(),
                             planes_.address(),
                             target_.width(),
                             target_.height(),
                             static_cast<std::uint32_t>(shape.luma_stride()),
                             static_cast<std::uint32_t>(shape.chroma_rows())};
  const std::uint64_t blocks = std::uint64_t(shape.luma_stride() / 8) * shape.chroma_rows();
  pipelines_->yuv420.dispatch(commands, convert, blocks);
  memory_barrier(commands, kCompute, VK_ACCESS_SHADER_WRITE_BIT, kTransfer,
                 VK_ACCESS_TRANSFER_READ_BIT);
  const VkBufferCopy copy{0, 0, frame_bytes(FrameFormat::yuv420)};
  vkCmdCopyBuffer(commands, planes_.get(), slot.readback.get(), 1, &copy);
}

}  // namespace fluidcast::render

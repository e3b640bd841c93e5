// Renders frames offscreen and reads them back: the particles are read where they are (the GPU
// solver's buffers, or a ParticleUpload of a CPU solver's), nothing else crosses to the GPU.
// Two modes today: points (diagnosis) and SSFR; Marching Cubes is still to come (issue 4).
#pragma once

#include <glm/glm.hpp>
#include <memory>
#include <string_view>
#include <vector>

#include "fluidcast/codec/image.h"
#include "fluidcast/gpu/buffer.h"
#include "fluidcast/gpu/command_slot.h"
#include "fluidcast/gpu/compute_pipeline.h"
#include "fluidcast/render/camera.h"
#include "fluidcast/render/render_target.h"
#include "fluidcast/sim/particles.h"

namespace fluidcast::render {

class GraphicsPipeline;

enum class RendererKind { points, ssfr };
const std::vector<std::string_view>& renderer_names();
RendererKind parse_renderer(std::string_view name);  // throws std::invalid_argument listing them

// Where the particles are on the GPU: vec4 positions and velocities (w unused).
struct ParticleView {
  VkDeviceAddress position = 0;
  VkDeviceAddress velocity = 0;
  std::uint32_t count = 0;
  float radius = 0.01f;  // m
};

struct PointsStyle {
  glm::vec3 slow_colour{0.10f, 0.35f, 0.85f};
  glm::vec3 fast_colour{0.90f, 0.95f, 1.00f};
  float full_speed = 2.0f;  // m/s that get fast_colour
};

struct SsfrStyle {
  // Of the depth filter, in particle radii (a length in the scene: view-invariant).
  float smoothing_radii = 4.0f;
  // Rounds of the separable filter (x then y): more is smoother and costs more.
  int smoothing_passes = 2;
  // Depth difference, in particle radii, that the filter treats as a different surface.
  float depth_falloff_radii = 2.0f;
  // Beer–Lambert absorption per metre of water: red goes first, so thick water turns blue-green.
  glm::vec3 absorption{6.0f, 1.8f, 0.9f};
};

class FrameRenderer {
 public:
  // Throws std::invalid_argument for a size of zero or beyond the device's limits.
  FrameRenderer(gpu::Context& context, std::uint32_t width, std::uint32_t height);
  ~FrameRenderer();

  PointsStyle points;
  SsfrStyle ssfr;

  // Draws one frame of the particles in `tank` and returns it (waits for it). Throws
  // std::invalid_argument for a camera that is not finite or out of range.
  codec::ImageRgba render(RendererKind kind, const ParticleView& particles, const sim::Box& tank,
                          const OrbitCamera& camera);

 private:
  gpu::Context* context_;
  RenderTarget target_;
  std::unique_ptr<GraphicsPipeline> background_, points_, fluid_surface_;
  gpu::ComputePipeline smooth_, shade_;
  gpu::Buffer frame_params_;
  // SSFR, one value per pixel: nearest fluid distance (and a filtered copy), thickness, the
  // scene behind, and the finished frame.
  gpu::Buffer depth_, depth_scratch_, thickness_, scene_, image_;
  gpu::Buffer readback_;
  gpu::CommandSlot commands_;
};

}  // namespace fluidcast::render

#include "fluidcast/render/frame_renderer.h"

#include <cstring>

#include "frame_params.h"
#include "points_pass.h"

namespace fluidcast::render {
namespace {

void barrier(VkCommandBuffer commands, VkPipelineStageFlags from, VkAccessFlags written,
             VkPipelineStageFlags to, VkAccessFlags accessed) {
  VkMemoryBarrier memory{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  memory.srcAccessMask = written;
  memory.dstAccessMask = accessed;
  vkCmdPipelineBarrier(commands, from, to, 0, 1, &memory, 0, nullptr, 0, nullptr);
}

constexpr VkPipelineStageFlags kDrawStages =
    VK_PIPELINE_STAGE_VERTEX_SHADER_BIT | VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT;

}  // namespace

FrameRenderer::FrameRenderer(gpu::Context& context, std::uint32_t width, std::uint32_t height)
    : context_(&context),
      target_(context, width, height),
      points_pass_(std::make_unique<PointsPass>(context, target_.render_pass())),
      frame_params_(context, sizeof(FrameParams), gpu::MemoryDomain::device),
      readback_(context, std::uint64_t{width} * height * 4, gpu::MemoryDomain::readback),
      commands_(context) {}

FrameRenderer::~FrameRenderer() { commands_.wait(); }

codec::ImageRgba FrameRenderer::render(const ParticleView& particles, const OrbitCamera& camera) {
  camera.validate();
  const std::uint32_t width = target_.width(), height = target_.height();
  FrameParams frame{};
  frame.view = camera.view();
  frame.projection = camera.projection(float(width) / float(height));
  frame.light_direction = glm::vec4(glm::normalize(glm::vec3(0.4f, 0.8f, 0.6f)), 0.0f);
  frame.slow_colour = glm::vec4(points.slow_colour, 1.0f);
  frame.fast_colour = glm::vec4(points.fast_colour, 1.0f);
  frame.particle_radius = particles.radius;
  frame.full_speed = points.full_speed;

  const VkCommandBuffer commands = commands_.begin();
  // The solver's writes (compute, transfers) before this frame reads the particles in place.
  barrier(commands, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
          VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT,
          kDrawStages | VK_PIPELINE_STAGE_TRANSFER_BIT,
          VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_TRANSFER_WRITE_BIT);
  vkCmdUpdateBuffer(commands, frame_params_.get(), 0, sizeof(frame), &frame);
  barrier(commands, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT, kDrawStages,
          VK_ACCESS_SHADER_READ_BIT);
  const float clear[4] = {background.r, background.g, background.b, background.a};
  target_.begin(commands, clear);
  if (particles.count > 0) {
    points_pass_->record(commands, {frame_params_.address(), particles.position, particles.velocity},
                         particles.count);
  }
  target_.end(commands);

  VkBufferImageCopy region{};
  region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  region.imageExtent = {width, height, 1};
  vkCmdCopyImageToBuffer(commands, target_.colour().get(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                         readback_.get(), 1, &region);
  // The solver's next step writes what this frame read (write after read), and the host reads
  // the copy.
  barrier(commands, kDrawStages, 0, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, 0);
  barrier(commands, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
          VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_HOST_READ_BIT);
  commands_.submit();
  commands_.wait();

  codec::ImageRgba image(static_cast<int>(width), static_cast<int>(height));
  std::memcpy(image.pixels.data(), readback_.mapped<std::uint8_t>().data(), image.pixels.size());
  return image;
}

}  // namespace fluidcast::render

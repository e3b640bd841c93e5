// C++ mirror of shaders/common/frame.glsl and the push constants of the render passes (std430).
#pragma once

#include <vulkan/vulkan.h>

#include <cstddef>
#include <glm/glm.hpp>

namespace fluidcast::render {

struct FrameParams {
  glm::mat4 view;
  glm::mat4 projection;
  glm::mat4 inverse_view;
  glm::vec4 light_direction;
  glm::vec4 slow_colour;
  glm::vec4 fast_colour;
  glm::vec4 tank_min;
  glm::vec4 tank_max;
  glm::vec4 absorption;
  float particle_radius;
  float full_speed;
  float smoothing_radius;
  float depth_falloff;
  std::uint32_t width;
  std::uint32_t height;
  std::uint32_t colour_by_density;
  float density_span;
};
static_assert(offsetof(FrameParams, inverse_view) == 128);
static_assert(offsetof(FrameParams, light_direction) == 192);
static_assert(offsetof(FrameParams, absorption) == 272);
static_assert(offsetof(FrameParams, particle_radius) == 288);
static_assert(offsetof(FrameParams, width) == 304);
static_assert(sizeof(FrameParams) % 16 == 0);

// shaders/common/draw_pass.glsl
struct DrawConstants {
  VkDeviceAddress frame, vertices;
};
static_assert(offsetof(DrawConstants, vertices) == 8 && sizeof(DrawConstants) == 16);

// shaders/common/particle_splat.glsl
enum class SplatMode : std::uint32_t { ssfr, points_distance, points_colour };
struct SplatConstants {
  VkDeviceAddress frame, position, velocity, density_ratio, shape, distance, thickness, spray,
      image, large;
  std::uint32_t particle_count;
  std::uint32_t ellipsoids;
  std::uint32_t large_capacity;
  std::uint32_t mode;  // a SplatMode
};
static_assert(offsetof(SplatConstants, particle_count) == 80 && sizeof(SplatConstants) == 96);

// shaders/common/screen_pass.glsl
struct ScreenConstants {
  VkDeviceAddress frame, depth_in, depth_out, thickness, spray, scene, image;
  std::uint32_t axis;
  std::uint32_t narrow_range;
};
static_assert(offsetof(ScreenConstants, axis) == 56 &&
              offsetof(ScreenConstants, narrow_range) == 60);

// shaders/common/anisotropy_pass.glsl
struct AnisotropyConstants {
  glm::vec4 origin;
  glm::ivec4 dims;
  VkDeviceAddress position, order, cell_start, sorted_cell, sorted_position, centre, shape;
  std::uint32_t particle_count;
  float radius, search_radius, max_stretch, centre_smoothing;
  std::uint32_t spray_below;
  std::uint32_t max_candidates;
};
static_assert(offsetof(AnisotropyConstants, position) == 32 &&
              offsetof(AnisotropyConstants, particle_count) == 88 &&
              offsetof(AnisotropyConstants, max_candidates) == 112);

// shaders/render/yuv420.comp
struct YuvConstants {
  VkDeviceAddress image, planes;
  std::uint32_t width, height, luma_stride, chroma_rows;
};
static_assert(offsetof(YuvConstants, width) == 16 && sizeof(YuvConstants) == 32);

}  // namespace fluidcast::render

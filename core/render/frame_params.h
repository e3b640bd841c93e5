// C++ mirror of shaders/common/frame.glsl (std430).
#pragma once

#include <vulkan/vulkan.h>

#include <cstddef>
#include <glm/glm.hpp>

namespace fluidcast::render {

struct FrameParams {
  glm::mat4 view;
  glm::mat4 projection;
  glm::vec4 light_direction;
  glm::vec4 slow_colour;
  glm::vec4 fast_colour;
  float particle_radius;
  float full_speed;
  float padding[2];
};
static_assert(offsetof(FrameParams, projection) == 64);
static_assert(offsetof(FrameParams, light_direction) == 128);
static_assert(offsetof(FrameParams, particle_radius) == 176);
static_assert(sizeof(FrameParams) % 16 == 0);

struct DrawConstants {
  VkDeviceAddress frame, position, velocity;
};
static_assert(sizeof(DrawConstants) == 24);

}  // namespace fluidcast::render

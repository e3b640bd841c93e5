#include "fluidcast/render/surface_roughness.h"

#include <cmath>
#include <stdexcept>
#include <vector>

namespace fluidcast::render {
namespace {

glm::vec3 view_position(int x, int y, float distance, const glm::mat4& projection,
                        std::uint32_t width, std::uint32_t height) {
  const glm::vec2 ndc = (glm::vec2(x, y) + 0.5f) / glm::vec2(width, height) * 2.0f - 1.0f;
  return distance * glm::vec3(ndc.x / projection[0][0], ndc.y / projection[1][1], -1.0f);
}

}  // namespace

SurfaceRoughness measure_roughness(std::span<const float> distance, std::uint32_t width,
                                   std::uint32_t height, const glm::mat4& projection,
                                   float degrees) {
  if (distance.size() != std::size_t{width} * height) {
    throw std::invalid_argument("surface roughness: the distances do not match the frame size");
  }
  const auto w = static_cast<int>(width), h = static_cast<int>(height);
  const auto at = [&](int x, int y) { return distance[std::size_t(y) * width + std::size_t(x)]; };
  const auto fluid = [&](int x, int y) {
    return x >= 0 && y >= 0 && x < w && y < h && std::isfinite(at(x, y));
  };
  // Normals where a pixel and its four neighbours are fluid: central differences.
  std::vector<glm::vec3> normal(distance.size(), glm::vec3(0.0f));
  for (int y = 1; y + 1 < h; ++y) {
    for (int x = 1; x + 1 < w; ++x) {
      if (!fluid(x, y) || !fluid(x - 1, y) || !fluid(x + 1, y) || !fluid(x, y - 1) ||
          !fluid(x, y + 1)) {
        continue;
      }
      const glm::vec3 dx = view_position(x + 1, y, at(x + 1, y), projection, width, height) -
                           view_position(x - 1, y, at(x - 1, y), projection, width, height);
      const glm::vec3 dy = view_position(x, y + 1, at(x, y + 1), projection, width, height) -
                           view_position(x, y - 1, at(x, y - 1), projection, width, height);
      glm::vec3 n = glm::cross(dy, dx);
      const float length = glm::length(n);
      if (!(length > 0.0f)) continue;
      n /= length;
      normal[std::size_t(y) * width + std::size_t(x)] = n.z < 0.0f ? -n : n;
    }
  }
  const float cos_limit = std::cos(glm::radians(degrees));
  SurfaceRoughness result;
  std::uint64_t rough = 0;
  for (int y = 1; y + 1 < h; ++y) {
    for (int x = 1; x + 1 < w; ++x) {
      const glm::vec3 n = normal[std::size_t(y) * width + std::size_t(x)];
      if (n == glm::vec3(0.0f)) continue;
      glm::vec3 sum(0.0f);
      bool all = true;
      for (int dy = -1; dy <= 1 && all; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          if (dx == 0 && dy == 0) continue;
          const glm::vec3 m = normal[std::size_t(y + dy) * width + std::size_t(x + dx)];
          if (m == glm::vec3(0.0f)) {
            all = false;
            break;
          }
          sum += m;
        }
      }
      if (!all) continue;  // at a silhouette
      ++result.pixels;
      if (glm::dot(n, glm::normalize(sum)) < cos_limit) ++rough;
    }
  }
  result.rough_share = result.pixels > 0 ? double(rough) / double(result.pixels) : 0.0;
  return result;
}

}  // namespace fluidcast::render

// How smooth a rendered fluid surface is, as a number: the share of the surface's pixels whose
// normal turns more than `degrees` from the mean normal of the 8 pixels around it. A surface that
// reads as water (smooth, with the waves the fluid has) scores a few per cent; one where every
// sphere still shows scores tens of per cent, and shading turns it into specular speckle. Normals
// come from central differences of the view positions after smoothing
// (FrameRenderer::surface_distances()); pixels at a silhouette are left out.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <span>

namespace fluidcast::render {

struct SurfaceRoughness {
  double rough_share = 0.0;  // of the pixels measured, 0 to 1
  std::uint64_t pixels = 0;  // measured: fluid all around
};

// `distance`: width × height view distances, rows top to bottom, +inf where there is no fluid;
// `projection`: the frame's. Throws std::invalid_argument for a size that does not match.
SurfaceRoughness measure_roughness(std::span<const float> distance, std::uint32_t width,
                                   std::uint32_t height, const glm::mat4& projection,
                                   float degrees = 20.0f);

}  // namespace fluidcast::render

// SSFR's particle pass (particle_splat.comp and particle_splat_large.comp) against the same spheres
// ray-cast on the CPU in double precision: the nearest surface's view distance at every pixel,
// for particles small enough for one invocation, large enough for a workgroup each, and more
// large ones than the queue of workgroups holds.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <vector>

#include "fluidcast/render/frame_renderer.h"
#include "fluidcast/render/particle_source.h"
#include "render_test_support.h"

namespace fluidcast::render {
namespace {

constexpr double kNone = std::numeric_limits<double>::infinity();

// Per pixel, rows from the top: the view distance (along −z) of the nearest sphere's front on
// the ray through the pixel's centre, as the shading reads it back; kNone where no sphere is.
// Each sphere is tried over a generous square around its centre's pixel, so that the renderer's
// own bounds are tested, not copied.
std::vector<double> ray_cast(const std::vector<glm::vec3>& centres, double radius,
                             const glm::mat4& view, const glm::mat4& projection, int width,
                             int height) {
  std::vector<double> nearest(std::size_t(width) * height, kNone);
  const double px = projection[0][0], py = projection[1][1];
  for (const glm::vec3& world : centres) {
    const glm::dvec3 c = glm::dvec3(view * glm::vec4(world, 1.0f));
    const double ahead = -c.z;
    const double cx = (c.x / ahead * px + 1.0) * 0.5 * width - 0.5;
    const double cy = (c.y / ahead * py + 1.0) * 0.5 * height - 0.5;
    const double reach = 2.0 * radius / (ahead - radius) * 0.5 * std::max(px * width, py * height);
    for (int y = std::max(0, int(cy - reach)); y <= std::min(height - 1, int(cy + reach)); ++y) {
      for (int x = std::max(0, int(cx - reach)); x <= std::min(width - 1, int(cx + reach)); ++x) {
        const glm::dvec3 ray((((x + 0.5) / width) * 2.0 - 1.0) / px,
                             (((y + 0.5) / height) * 2.0 - 1.0) / py, -1.0);
        const glm::dvec3 direction = glm::normalize(ray);
        const double along = glm::dot(direction, c);
        const double discriminant = along * along - (glm::dot(c, c) - radius * radius);
        if (discriminant < 0.0) continue;
        const double enter = along - std::sqrt(discriminant);
        double& at = nearest[std::size_t(y) * width + x];
        at = std::min(at, -enter * direction.z);
      }
    }
  }
  return nearest;
}

// A point `depth` ahead of the camera, at (u, v) of the frame's half-widths from its centre.
glm::vec3 in_view(const glm::mat4& view, const glm::mat4& projection, float u, float v,
                  float depth) {
  const glm::vec4 in_eye(u * depth / projection[0][0], v * depth / projection[1][1], -depth, 1.0f);
  return glm::vec3(glm::inverse(view) * in_eye);
}

constexpr int kWidth = 320, kHeight = 240;
constexpr float kRadius = 0.03f;

// The left of the frame: 90,000 near particles, each over more pixels than one invocation casts
// (about 11 to 17 across), more than the queue of workgroups holds (65,535); the right: far ones,
// a few pixels across, each cast by its own invocation. At rest: points draws them in one colour.
std::vector<glm::vec3> near_and_far(const glm::mat4& view, const glm::mat4& projection) {
  std::mt19937 random(7);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  std::vector<glm::vec3> centres;
  for (int k = 0; k < 90000; ++k) {
    centres.push_back(in_view(view, projection, -0.95f + 0.95f * unit(random),
                              -0.95f + 1.9f * unit(random), 1.0f + 0.6f * unit(random)));
  }
  for (int k = 0; k < 3000; ++k) {
    centres.push_back(in_view(view, projection, 0.1f + unit(random), -1.0f + 2.0f * unit(random),
                              3.0f + unit(random)));
  }
  return centres;
}

sim::ParticleSet at_rest(const std::vector<glm::vec3>& centres) {
  sim::ParticleSet particles;
  for (const glm::vec3& centre : centres) particles.append(centre, {0, 0, 0}, 0);
  return particles;
}

// The near and far particles, uploaded, and the camera that sees them.
class ParticlePassTest : public RenderTest {
 protected:
  const OrbitCamera camera = looking_at_tank();
  const glm::mat4 view = camera.view();
  const glm::mat4 projection = camera.projection(float(kWidth) / kHeight);
  const std::vector<glm::vec3> centres = near_and_far(view, projection);
  ParticleSource source{context()};
  const ParticleView drawn = source.upload(at_rest(centres), kRadius);
};

TEST_F(ParticlePassTest, TheParticlePassGivesTheNearestSurfaceOfEverySphere) {
  FrameRenderer renderer(context(), kWidth, kHeight);
  renderer.ssfr.anisotropic = false;
  renderer.ssfr.smoothing_passes = 0;  // the distances as the particle pass left them
  keep(rgba(renderer.render(RendererKind::ssfr, drawn, kTank, camera)), "ssfr_splat_spheres");
  const std::vector<float> distances = renderer.surface_distances();
  const std::vector<double> expected =
      ray_cast(centres, kRadius, view, projection, kWidth, kHeight);

  std::size_t agree = 0, covered_left = 0, covered_right = 0;
  for (std::size_t i = 0; i < expected.size(); ++i) {
    const double got = distances[i], want = expected[i];
    if (std::isinf(want) ? std::isinf(got) : std::abs(got - want) <= 1e-4 * want) ++agree;
    if (!std::isinf(want)) ++(i % kWidth < kWidth / 2 ? covered_left : covered_right);
  }
  // Outlines' edge pixels, where the ray grazes a sphere, may go either way in float.
  EXPECT_GE(double(agree), 0.995 * double(expected.size()))
      << agree << " of " << expected.size() << " pixels agree";
  EXPECT_GT(covered_left, std::size_t(0.9 * kWidth / 2 * kHeight));
  EXPECT_GT(covered_right, std::size_t(0.2 * kWidth / 2 * kHeight));
}

// Points: each particle a disc facing the camera in the plane of its centre. Wherever a disc
// covers a pixel's centre, the pixel shows a particle, not the scene: the second pass, which
// colours the pixel by the particle whose distance the first pass kept, finds it, however each
// pass cast it (its own invocation, a queued workgroup, or its own again past the queue's end).
TEST_F(ParticlePassTest, PointsCoverEveryPixelTheirDiscsCover) {
  FrameRenderer renderer(context(), kWidth, kHeight);
  const auto scene = rgba(renderer.render(RendererKind::points, {}, kTank, camera));
  const auto points = rgba(renderer.render(RendererKind::points, drawn, kTank, camera));
  keep(points, "points_splat");
  std::vector<bool> covered(std::size_t(kWidth) * kHeight, false);
  const double px = projection[0][0], py = projection[1][1];
  for (const glm::vec3& world : centres) {
    const glm::dvec3 c = glm::dvec3(view * glm::vec4(world, 1.0f));
    for (int y = 0; y < kHeight; ++y) {
      const double ray_y = (((y + 0.5) / kHeight) * 2.0 - 1.0) / py * -c.z;
      if (std::abs(ray_y - c.y) > kRadius) continue;
      for (int x = 0; x < kWidth; ++x) {
        const double ray_x = (((x + 0.5) / kWidth) * 2.0 - 1.0) / px * -c.z;
        const double dx = ray_x - c.x, dy = ray_y - c.y;
        if (dx * dx + dy * dy <= 0.999 * kRadius * kRadius)
          covered[std::size_t(y) * kWidth + x] = true;
      }
    }
  }
  std::size_t covered_pixels = 0, holes = 0;
  for (std::size_t i = 0; i < covered.size(); ++i) {
    if (!covered[i]) continue;
    ++covered_pixels;
    if (std::equal(points.pixels.begin() + 4 * i, points.pixels.begin() + 4 * i + 3,
                   scene.pixels.begin() + 4 * i)) {
      ++holes;
    }
  }
  EXPECT_GT(covered_pixels, std::size_t(kWidth * kHeight / 2));
  EXPECT_EQ(holes, 0u) << "of " << covered_pixels << " pixels the discs cover";
}

}  // namespace
}  // namespace fluidcast::render

// The fluid's surface on lavapipe: depth smoothing and the roughness measure, the default filter
// on still and splashing water, spray, the narrow-range filter, thickness, absorption, points
// coloured by density, and the probe under a finger. Frames are kept in build/test-output/.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <random>

#include "fluidcast/codec/png.h"
#include "fluidcast/render/frame_renderer.h"
#include "fluidcast/render/particle_source.h"
#include "fluidcast/render/surface_roughness.h"
#include "render_test_support.h"

namespace fluidcast::render {
namespace {

// Without the depth filter every sphere shows in the normals; with it the surface is smooth. The
// measure: mean |Laplacian| of brightness over the pixels that show water.
TEST_F(RenderTest, DepthSmoothingLowersSurfaceNoise) {
  auto pool = drop_of(3000);
  ParticleSource source(context());
  const ParticleView view = source.view_of(*pool);
  FrameRenderer renderer(context(), 320, 180);
  const OrbitCamera camera = camera_on(pool->tank(), 1.6f);
  const auto empty = rgba(renderer.render(RendererKind::ssfr, {}, pool->tank(), camera));
  const auto noise = [&](const codec::ImageRgba& image) {
    const auto brightness = [&](int x, int y) {
      const std::uint8_t* p = image.pixel(x, y);
      return double(p[0]) + p[1] + p[2];
    };
    double sum = 0.0;
    std::size_t count = 0;
    for (int y = 1; y + 1 < image.height; ++y) {
      for (int x = 1; x + 1 < image.width; ++x) {
        if (std::memcmp(image.pixel(x, y), empty.pixel(x, y), 3) == 0) continue;
        sum += std::abs(4 * brightness(x, y) - brightness(x - 1, y) - brightness(x + 1, y) -
                        brightness(x, y - 1) - brightness(x, y + 1));
        ++count;
      }
    }
    return count > 0 ? sum / double(count) : 0.0;
  };
  renderer.ssfr.smoothing_passes = 0;
  const auto raw = rgba(renderer.render(RendererKind::ssfr, view, pool->tank(), camera));
  keep(raw, "render_pool_ssfr_unsmoothed");
  renderer.ssfr.smoothing_passes = 2;
  const auto smoothed = rgba(renderer.render(RendererKind::ssfr, view, pool->tank(), camera));
  keep(smoothed, "render_pool_ssfr_smoothed");
  std::printf("surface noise: %.1f unsmoothed, %.1f smoothed\n", noise(raw), noise(smoothed));
  EXPECT_LT(noise(smoothed), 0.7 * noise(raw));
}

// The roughness measure itself: a plane scores 0, a surface of random bumps most of its pixels.
TEST(SurfaceRoughness, APlaneIsSmoothAndRandomBumpsAreRough) {
  constexpr std::uint32_t w = 64, h = 48;
  const glm::mat4 projection = OrbitCamera{}.projection(float(w) / float(h));
  std::vector<float> plane(w * h, 2.0f), bumps(w * h);
  std::mt19937 random(7);
  std::uniform_real_distribution<float> jitter(-0.1f, 0.1f);
  for (float& d : bumps) d = 2.0f + jitter(random);
  const SurfaceRoughness flat = measure_roughness(plane, w, h, projection);
  EXPECT_EQ(flat.pixels, std::uint64_t{(w - 4) * (h - 4)});
  EXPECT_EQ(flat.rough_share, 0.0);
  EXPECT_GT(measure_roughness(bumps, w, h, projection).rough_share, 0.5);
  std::vector<float> none(w * h, std::numeric_limits<float>::infinity());
  EXPECT_EQ(measure_roughness(none, w, h, projection).pixels, 0u);
  EXPECT_THROW(measure_roughness(plane, w, h + 1, projection), std::invalid_argument);
}

// A resting pool, as the shading sees it: with the default filter the surface reads as water
// (few pixels turn from their neighbours); without it, every sphere shows.
TEST_F(RenderTest, TheDefaultFilterLeavesASurfaceThatReadsAsWater) {
  auto pool = drop_of(3000);
  ParticleSource source(context());
  const ParticleView view = source.view_of(*pool);
  constexpr std::uint32_t w = 320, h = 180;
  FrameRenderer renderer(context(), w, h);
  const OrbitCamera camera = camera_on(pool->tank(), 1.2f);
  const glm::mat4 projection = camera.projection(float(w) / float(h));
  const auto rough = [&] {
    renderer.render(RendererKind::ssfr, view, pool->tank(), camera);
    return measure_roughness(renderer.surface_distances(), w, h, projection);
  };
  renderer.ssfr.smoothing_passes = 0;
  const SurfaceRoughness raw = rough();
  renderer.ssfr = SsfrStyle{};
  const SurfaceRoughness smoothed = rough();
  std::printf(
      "rough pixels (over 20 degrees from their neighbours): %.1f %% of %llu unsmoothed, "
      "%.1f %% of %llu with the default filter\n",
      100.0 * raw.rough_share, static_cast<unsigned long long>(raw.pixels),
      100.0 * smoothed.rough_share, static_cast<unsigned long long>(smoothed.pixels));
  EXPECT_GT(smoothed.pixels, 1000u);
  EXPECT_GT(raw.rough_share, 0.1);
  EXPECT_LT(smoothed.rough_share, 0.05);
}

// A splashing dam break (8000 particles, t = 0.5 s): whether the spheres' bumps read as one
// surface. The defaults (ellipsoids, a depth range of 4 radii) against half that range, and
// against spheres.
TEST_F(RenderTest, TheDefaultsSmoothASplashingDamBreak) {
  sim::SceneParams scene;
  scene.kind = sim::SceneKind::dam_break;
  scene.particles = 8000;
  auto dam = sim::make_cpu_solver(sim::SolverKind::pbf, sim::build_scene(scene), {});
  while (dam->time() < 0.5) dam->step();
  ParticleSource source(context());
  const ParticleView view = source.view_of(*dam);
  constexpr std::uint32_t w = 640, h = 360;
  FrameRenderer renderer(context(), w, h);
  renderer.ssfr = SsfrStyle{};  // ellipsoids, as on a GPU
  OrbitCamera camera = camera_on(dam->tank(), 1.3f * glm::length(dam->tank().size()));
  camera.yaw_degrees = 20.0f;
  camera.pitch_degrees = 25.0f;
  const auto rough = [&](const char* name) {
    keep(rgba(renderer.render(RendererKind::ssfr, view, dam->tank(), camera)), name);
    return measure_roughness(renderer.surface_distances(), w, h,
                             camera.projection(float(w) / float(h)))
        .rough_share;
  };
  const double by_default = rough("render_dam_break_surface_default");
  renderer.ssfr.depth_falloff_radii = 0.5f * SsfrStyle{}.depth_falloff_radii;
  const double narrower = rough("render_dam_break_surface_narrower_range");
  renderer.ssfr = SsfrStyle{};
  renderer.ssfr.anisotropic = false;
  const double spheres = rough("render_dam_break_surface_spheres");
  std::printf(
      "rough pixels: %.1f %% by default, %.1f %% with half the depth range, %.1f %% "
      "with spheres\n",
      100.0 * by_default, 100.0 * narrower, 100.0 * spheres);
  EXPECT_LT(by_default, 0.03);
  EXPECT_GT(narrower, 2.0 * by_default);
  EXPECT_GT(spheres, 3.0 * by_default);
}

// A particle far from the rest is spray: drawn, white over the scene, but no part of the surface
// that the shading lights; as a sphere (no spray, or no anisotropy) it is the surface again.
TEST_F(RenderTest, ALoneParticleIsSprayNotSurface) {
  sim::ParticleSet one;
  one.append({0.5f, 0.2f, 0.15f}, {0, 0, 0}, 0);
  ParticleSource source(context());
  const ParticleView view = source.upload(one, 0.02f);
  constexpr std::uint32_t w = 160, h = 120;
  FrameRenderer renderer(context(), w, h);
  renderer.ssfr = SsfrStyle{};  // ellipsoids and spray, as on a GPU
  OrbitCamera camera = looking_at_tank();
  camera.distance = 0.5f;
  const auto empty = rgba(renderer.render(RendererKind::points, {}, kTank, camera));
  const auto surface_pixels = [&] {
    std::size_t pixels = 0;
    for (float d : renderer.surface_distances()) pixels += std::isfinite(d) ? 1 : 0;
    return pixels;
  };
  const auto spray = rgba(renderer.render(RendererKind::ssfr, view, kTank, camera));
  keep(spray, "render_one_particle_spray");
  EXPECT_EQ(surface_pixels(), 0u);
  EXPECT_GT(pixels_differing(spray, empty), 40u);
  const std::uint8_t* centre = spray.pixel(w / 2, h / 2);
  EXPECT_GT(std::min({centre[0], centre[1], centre[2]}), empty.pixel(w / 2, h / 2)[0])
      << "spray is lighter than what is behind it";
  renderer.ssfr.spray_neighbours = 0;
  renderer.render(RendererKind::ssfr, view, kTank, camera);
  EXPECT_GT(surface_pixels(), 40u);
  renderer.ssfr = SsfrStyle{};
  renderer.ssfr.anisotropic = false;
  renderer.render(RendererKind::ssfr, view, kTank, camera);
  EXPECT_GT(surface_pixels(), 40u);
}

// The two depth filters side by side, kept for the eye (build/test-output/render_filter_*.png);
// the narrow-range filter must smooth too, and must differ from the bilateral one.
TEST_F(RenderTest, NarrowRangeFilterSmoothsAndDiffersFromBilateral) {
  sim::SceneParams scene;
  scene.particles = 4000;
  auto solver = sim::make_gpu_solver(sim::SolverKind::pbf, context(), sim::build_scene(scene), {});
  for (int k = 0; k < 40; ++k) solver->step();
  ParticleSource source(context());
  const ParticleView view = source.view_of(*solver);
  FrameRenderer renderer(context(), 320, 180);
  const OrbitCamera camera = camera_on(solver->tank(), 2.0f);
  renderer.ssfr.smoothing_passes = 0;
  const auto raw = rgba(renderer.render(RendererKind::ssfr, view, solver->tank(), camera));
  renderer.ssfr.smoothing_passes = 2;
  renderer.ssfr.filter = SsfrStyle::DepthFilter::bilateral;
  const auto bilateral = rgba(renderer.render(RendererKind::ssfr, view, solver->tank(), camera));
  renderer.ssfr.filter = SsfrStyle::DepthFilter::narrow_range;
  const auto narrow = rgba(renderer.render(RendererKind::ssfr, view, solver->tank(), camera));
  keep(raw, "render_filter_none");
  keep(bilateral, "render_filter_bilateral");
  keep(narrow, "render_filter_narrow_range");
  EXPECT_GT(pixels_differing(narrow, bilateral), 100u);
  EXPECT_GT(pixels_differing(narrow, raw), 100u);
}

// Looking straight down into a pool: three times the water over the same floor is darker.
TEST_F(RenderTest, MoreThicknessDarkensTheWater) {
  FrameRenderer renderer(context(), 96, 96);
  // Ellipsoids, as on a GPU: spheres on the lattice at rest leave specular streaks in the middle
  // of the shallow pool, light that has nothing to do with the water's depth.
  renderer.ssfr = SsfrStyle{};
  ParticleSource source(context());
  // 2000 particles a tenth of a metre deep: the same spacing at every depth.
  const auto centre_brightness = [&](int tenths_of_a_metre) {
    sim::SceneParams scene;
    scene.kind = sim::SceneKind::pool;
    scene.pool_height = 0.1f * static_cast<float>(tenths_of_a_metre);
    scene.particles = 2000 * tenths_of_a_metre;
    auto pool = sim::make_cpu_solver(sim::SolverKind::pbf, sim::build_scene(scene), {});
    OrbitCamera camera;
    camera.target = 0.5f * (pool->tank().min + pool->tank().max);
    camera.pitch_degrees = 89.0f;
    camera.distance = 0.6f;
    const auto image =
        rgba(renderer.render(RendererKind::ssfr, source.view_of(*pool), pool->tank(), camera));
    keep(image, "render_pool_from_above_" + std::to_string(scene.particles));
    double sum = 0.0;
    for (int y = 40; y < 56; ++y)
      for (int x = 40; x < 56; ++x) sum += image.pixel(x, y)[0] + image.pixel(x, y)[1];
    return sum;
  };
  EXPECT_LT(centre_brightness(3), 0.9 * centre_brightness(1));
}

// Points coloured by ρ/ρ0: from the GPU solver's own densities, or measured for a CPU solver's
// particles; without densities, a clear refusal.
TEST_F(RenderTest, PointsColouredByDensity) {
  sim::SceneParams scene;
  scene.particles = 2000;
  auto gpu_solver =
      sim::make_gpu_solver(sim::SolverKind::pbf, context(), sim::build_scene(scene), {});
  for (int k = 0; k < 10; ++k) gpu_solver->step();
  FrameRenderer renderer(context(), 240, 135);
  const OrbitCamera camera = camera_on(gpu_solver->tank(), 2.2f);
  ParticleSource in_place(context());
  const ParticleView view = in_place.view_of(*gpu_solver);
  ASSERT_NE(view.density_ratio, 0u);
  const auto by_speed =
      rgba(renderer.render(RendererKind::points, view, gpu_solver->tank(), camera));
  renderer.points.colour_by = PointsStyle::ColourBy::density;
  const auto by_density =
      rgba(renderer.render(RendererKind::points, view, gpu_solver->tank(), camera));
  keep(by_density, "render_points_by_density");
  EXPECT_GT(pixels_differing(by_speed, by_density), 500u);

  auto cpu_solver = drop_of(2000);
  ParticleSource measured(context(), true);
  EXPECT_NO_THROW(rgba(renderer.render(RendererKind::points, measured.view_of(*cpu_solver),
                                       cpu_solver->tank(), camera)));
  ParticleSource without(context());
  EXPECT_THROW(renderer.render(RendererKind::points, without.view_of(*cpu_solver),
                               cpu_solver->tank(), camera),
               std::invalid_argument);
}

// A fluid on the GPU that has not stepped since it was loaded (a new session's first frame, a
// paused one after a snapshot) shows rest density, not whatever its new memory held.
TEST_F(RenderTest, AnUnsteppedGpuFluidIsColouredAtRestDensity) {
  sim::SceneParams scene;
  scene.kind = sim::SceneKind::pool;
  scene.particles = 2000;
  auto solver = sim::make_gpu_solver(sim::SolverKind::pbf, context(), sim::build_scene(scene), {});
  FrameRenderer renderer(context(), 240, 135);
  renderer.points.colour_by = PointsStyle::ColourBy::density;
  const OrbitCamera camera = camera_on(solver->tank(), 2.2f);
  ParticleSource in_place(context());
  const auto unstepped = rgba(
      renderer.render(RendererKind::points, in_place.view_of(*solver), solver->tank(), camera));
  const sim::ParticleSet particles = solver->snapshot();
  ParticleSource uploaded(context());
  const std::vector<float> at_rest(particles.size(), 1.0f);
  const auto expected = rgba(renderer.render(
      RendererKind::points, uploaded.upload(particles, solver->fluid().particle_radius(), at_rest),
      solver->tank(), camera));
  EXPECT_EQ(pixels_differing(unstepped, expected), 0u);
}

TEST_F(RenderTest, StrongerAbsorptionDarkensTheWater) {
  auto pool = drop_of(3000);
  ParticleSource source(context());
  const ParticleView view = source.view_of(*pool);
  FrameRenderer renderer(context(), 240, 135);
  const OrbitCamera camera = camera_on(pool->tank(), 2.0f);
  const auto empty = rgba(renderer.render(RendererKind::ssfr, {}, pool->tank(), camera));
  const auto mean_over_water = [&](const codec::ImageRgba& image) {
    double sum = 0.0;
    std::size_t count = 0;
    for (std::size_t i = 0; i < image.pixels.size(); i += 4) {
      if (image.pixels[i] == empty.pixels[i] && image.pixels[i + 1] == empty.pixels[i + 1])
        continue;
      sum += image.pixels[i] + image.pixels[i + 1] + image.pixels[i + 2];
      ++count;
    }
    return count > 0 ? sum / double(count) : 0.0;
  };
  const auto clear_water = rgba(renderer.render(RendererKind::ssfr, view, pool->tank(), camera));
  keep(clear_water, "render_pool_ssfr");
  renderer.ssfr.absorption *= 4.0f;
  const auto murky_water = rgba(renderer.render(RendererKind::ssfr, view, pool->tank(), camera));
  keep(murky_water, "render_pool_ssfr_murky");
  EXPECT_LT(mean_over_water(murky_water), 0.9 * mean_over_water(clear_water));
}

// Looking down into a pool: the probe under the frame's centre meets a particle's surface there
// (unsmoothed, so exactly a sphere's); a probe beside the tank meets nothing; points draw no
// surface to probe. (On the lattice at rest the ray may slip between spheres, so the depth of the
// hit is checked against the spheres themselves, not against the pool's height.)
TEST_F(RenderTest, TheProbeFindsTheSurfaceUnderAPoint) {
  auto pool = drop_of(3000);
  ParticleSource source(context());
  const ParticleView view = source.view_of(*pool);
  FrameRenderer renderer(context(), 160, 90);
  renderer.ssfr.smoothing_passes = 0;
  renderer.ssfr.anisotropic = false;  // spheres, where the hit is checked (a GPU's default is on)
  OrbitCamera camera = camera_on(pool->tank(), 2.0f);
  camera.pitch_degrees = 89.0f;
  renderer.probe = glm::vec2(0.5f, 0.5f);
  rgba(renderer.render(RendererKind::ssfr, view, pool->tank(), camera));
  const auto hit = renderer.last_probe_hit();
  ASSERT_TRUE(hit.has_value());
  const glm::vec3 centre = 0.5f * (pool->tank().min + pool->tank().max);
  const float spacing = pool->scene().spacing;
  EXPECT_NEAR(hit->x, centre.x, 2 * spacing);
  EXPECT_NEAR(hit->z, centre.z, 2 * spacing);
  EXPECT_LT(hit->y, pool->scene().params.pool_height + spacing);
  float nearest = 1e9f;
  for (const glm::vec3& p : pool->snapshot().position) {
    nearest = std::min(nearest, glm::length(p - *hit));
  }
  EXPECT_NEAR(nearest, view.radius, 0.25f * view.radius);
  renderer.probe = glm::vec2(0.5f, 0.02f);
  rgba(renderer.render(RendererKind::ssfr, view, pool->tank(), camera));
  EXPECT_FALSE(renderer.last_probe_hit().has_value());
  renderer.probe = glm::vec2(0.5f, 0.5f);
  rgba(renderer.render(RendererKind::points, view, pool->tank(), camera));
  EXPECT_FALSE(renderer.last_probe_hit().has_value());
  renderer.probe = glm::vec2(1.5f, 0.5f);
  EXPECT_THROW(renderer.render(RendererKind::ssfr, view, pool->tank(), camera),
               std::invalid_argument);
}

}  // namespace
}  // namespace fluidcast::render

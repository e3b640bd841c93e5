// Offscreen rendering on lavapipe: sizes (1×1, odd, the device's maximum and one past it), bad
// cameras, an empty scene, particles where they project, the GPU solver's buffers read in place
// against an uploaded copy, and SSFR's absorption. Frames are kept in build/test-output/ to look
// at.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <limits>
#include <random>
#include <set>
#include <utility>
#include <variant>

#include "fluidcast/codec/jpeg.h"
#include "fluidcast/codec/png.h"
#include "fluidcast/render/frame_renderer.h"
#include "fluidcast/render/particle_source.h"
#include "fluidcast/render/surface_roughness.h"
#include "gpu_test_support.h"

namespace fluidcast::render {
namespace {

using fluidcast::testing::GpuTest;
using fluidcast::testing::rgba;

const sim::Box kTank{{0, 0, 0}, {1.0f, 0.6f, 0.3f}};

OrbitCamera looking_at_tank() {
  OrbitCamera camera;
  camera.target = {0.5f, 0.2f, 0.15f};
  camera.distance = 1.6f;
  return camera;
}

std::size_t pixels_differing(const codec::ImageRgba& a, const codec::ImageRgba& b) {
  std::size_t count = 0;
  for (std::size_t i = 0; i < a.pixels.size(); i += 4) {
    for (int c = 0; c < 3; ++c) {
      if (std::abs(int(a.pixels[i + c]) - int(b.pixels[i + c])) > 2) {
        ++count;
        break;
      }
    }
  }
  return count;
}

// Keeps the image where a person can look at it: build/test-output/NAME.png.
void keep(const codec::ImageRgba& image, const std::string& name) {
  std::filesystem::create_directories("test-output");
  codec::write_png("test-output/" + name + ".png", image);
}

// Looking at the middle of `tank` from `distance` metres.
OrbitCamera camera_on(const sim::Box& tank, float distance) {
  OrbitCamera camera;
  camera.target = 0.5f * (tank.min + tank.max);
  camera.distance = distance;
  return camera;
}

std::unique_ptr<sim::Solver> drop_of(int particles) {
  sim::SceneParams scene;
  scene.kind = sim::SceneKind::pool;
  scene.particles = particles;
  return sim::make_cpu_solver(sim::SolverKind::pbf, sim::build_scene(scene), {});
}

class RenderTest : public GpuTest {};

TEST_F(RenderTest, AnEmptySceneIsTheSameInEveryMode) {
  FrameRenderer renderer(context(), 160, 90);
  const auto points = rgba(renderer.render(RendererKind::points, {}, kTank, looking_at_tank()));
  const auto ssfr = rgba(renderer.render(RendererKind::ssfr, {}, kTank, looking_at_tank()));
  const auto mc = rgba(renderer.render(RendererKind::mc, {}, kTank, looking_at_tank()));
  keep(points, "render_empty");
  EXPECT_EQ(points.pixels, ssfr.pixels);
  EXPECT_EQ(points.pixels, mc.pixels);
  // The scene is there: tank floor tiles, walls, room floor and sky differ.
  std::set<std::uint32_t> colours;
  for (std::size_t i = 0; i < points.pixels.size(); i += 4) {
    colours.insert(points.pixels[i] | points.pixels[i + 1] << 8 | points.pixels[i + 2] << 16);
  }
  EXPECT_GT(colours.size(), 20u);
}

// The scene is drawn once per camera and kept for the fluid frames after it: a kept scene must
// give the very image a fresh one does, and a moved camera, a points frame (which draws over the
// scene) or another tank must not keep a stale one.
TEST_F(RenderTest, AKeptSceneGivesTheSameFrameAsAFreshOne) {
  auto pool = drop_of(1500);
  ParticleSource source(context());
  const ParticleView view = source.view_of(*pool);
  const OrbitCamera near = camera_on(pool->tank(), 2.0f);
  OrbitCamera turned = near;
  turned.yaw_degrees += 30.0f;
  for (auto kind : {RendererKind::ssfr, RendererKind::mc}) {
    FrameRenderer fresh_renderer(context(), 160, 90);
    const auto fresh = rgba(fresh_renderer.render(kind, view, pool->tank(), near));
    FrameRenderer renderer(context(), 160, 90);
    const auto first = rgba(renderer.render(kind, view, pool->tank(), near));
    EXPECT_EQ(rgba(renderer.render(kind, view, pool->tank(), near)).pixels, fresh.pixels);
    const auto other = rgba(renderer.render(kind, view, pool->tank(), turned));
    EXPECT_NE(other.pixels, fresh.pixels);
    EXPECT_EQ(rgba(renderer.render(kind, view, pool->tank(), near)).pixels, fresh.pixels);
    rgba(renderer.render(RendererKind::points, view, pool->tank(), near));
    EXPECT_EQ(rgba(renderer.render(kind, view, pool->tank(), near)).pixels, fresh.pixels);
    sim::Box wider = pool->tank();
    wider.max.x += 0.5f;
    EXPECT_NE(rgba(renderer.render(kind, view, wider, near)).pixels, fresh.pixels);
    EXPECT_EQ(rgba(renderer.render(kind, view, pool->tank(), near)).pixels, fresh.pixels);
    EXPECT_EQ(first.pixels, fresh.pixels);
  }
}

TEST_F(RenderTest, OneByOneOddAndLargestSizesAndBeyond) {
  for (auto [w, h] : {std::pair{1u, 1u}, {33u, 17u}}) {
    FrameRenderer renderer(context(), w, h);
    for (auto kind : {RendererKind::points, RendererKind::ssfr, RendererKind::mc}) {
      EXPECT_EQ(rgba(renderer.render(kind, {}, kTank, looking_at_tank())).pixels.size(),
                std::size_t{w} * h * 4);
    }
  }
  const std::uint32_t largest = context().limits().maxFramebufferWidth;
  EXPECT_NO_THROW(FrameRenderer(context(), largest, 1));
  try {
    FrameRenderer(context(), largest + 1, 1);
    ADD_FAILURE() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(std::to_string(largest)), std::string::npos) << e.what();
  }
  EXPECT_THROW(FrameRenderer(context(), 0, 10), std::invalid_argument);
}

TEST_F(RenderTest, ANonFiniteCameraIsRefused) {
  FrameRenderer renderer(context(), 16, 16);
  OrbitCamera camera = looking_at_tank();
  camera.distance = std::numeric_limits<float>::quiet_NaN();
  EXPECT_THROW(renderer.render(RendererKind::points, {}, kTank, camera), std::invalid_argument);
  camera = looking_at_tank();
  camera.pitch_degrees = 95.0f;
  EXPECT_THROW(renderer.render(RendererKind::ssfr, {}, kTank, camera), std::invalid_argument);
}

TEST_F(RenderTest, AParticleShowsWhereItProjects) {
  const sim::ParticleSet one = [] {
    sim::ParticleSet set;
    set.append({0.5f, 0.2f, 0.15f}, {0, 0, 0}, 0);
    return set;
  }();
  ParticleSource source(context());
  const ParticleView view = source.upload(one, 0.02f);
  FrameRenderer renderer(context(), 160, 120);
  OrbitCamera camera = looking_at_tank();
  camera.distance = 0.5f;
  const auto empty = rgba(renderer.render(RendererKind::points, {}, kTank, camera));
  for (auto kind : {RendererKind::points, RendererKind::ssfr}) {
    const auto image = rgba(renderer.render(kind, view, kTank, camera));
    keep(image,
         kind == RendererKind::points ? "render_one_particle_points" : "render_one_particle_ssfr");
    const std::uint8_t *centre = image.pixel(80, 60), *behind = empty.pixel(80, 60);
    EXPECT_GT(std::abs(int(centre[0]) - behind[0]) + std::abs(int(centre[1]) - behind[1]) +
                  std::abs(int(centre[2]) - behind[2]),
              20)
        << "nothing drawn at the centre";
    // A sphere of radius 2 cm at 0.5 m with a 45° field of view: about 11 pixels across.
    const std::size_t drawn = pixels_differing(image, empty);
    EXPECT_GT(drawn, 40u);
    EXPECT_LT(drawn, 300u);
  }
}

TEST_F(RenderTest, GpuSolverBuffersInPlaceMatchAnUploadedCopy) {
  sim::SceneParams scene;
  scene.particles = 2000;
  auto solver = sim::make_gpu_solver(sim::SolverKind::pbf, context(), sim::build_scene(scene), {});
  for (int k = 0; k < 20; ++k) solver->step();
  ParticleSource source(context());
  FrameRenderer renderer(context(), 320, 180);
  const OrbitCamera camera = camera_on(solver->tank(), 2.4f);
  for (auto kind : {RendererKind::points, RendererKind::ssfr}) {
    const auto in_place =
        rgba(renderer.render(kind, source.view_of(*solver), solver->tank(), camera));
    keep(in_place,
         kind == RendererKind::points ? "render_dam_break_points" : "render_dam_break_ssfr");
    const auto uploaded = rgba(
        renderer.render(kind, source.upload(solver->snapshot(), solver->fluid().particle_radius()),
                        solver->tank(), camera));
    EXPECT_EQ(uploaded.pixels, in_place.pixels);
    const auto empty = rgba(renderer.render(kind, {}, solver->tank(), camera));
    EXPECT_GT(pixels_differing(in_place, empty), 2000u) << "the fluid is not in the frame";
  }
}

TEST_F(RenderTest, FramesInFlightComeBackInOrderAndNoneIsLostUntilTheCapOfKeptFrames) {
  auto pool = drop_of(1000);
  ParticleSource source(context());
  const ParticleView view = source.view_of(*pool);
  FrameRenderer renderer(context(), 64, 36);
  std::vector<OrbitCamera> cameras(5, looking_at_tank());
  std::vector<codec::ImageRgba> expected;
  for (std::size_t k = 0; k < cameras.size(); ++k) {
    cameras[k].yaw_degrees = 20.0f * static_cast<float>(k);
    expected.push_back(rgba(renderer.render(RendererKind::ssfr, view, pool->tank(), cameras[k])));
  }
  // Three submitted, none taken: two in flight, one kept; they come back oldest first.
  for (int k = 0; k < 3; ++k) renderer.submit(RendererKind::ssfr, view, pool->tank(), cameras[k]);
  EXPECT_EQ(renderer.frames_pending(), 3u);
  for (int k = 0; k < 3; ++k)
    EXPECT_EQ(rgba(renderer.take_oldest()).pixels, expected[k].pixels) << k;
  EXPECT_EQ(renderer.frames_pending(), 0u);
  EXPECT_THROW(renderer.take_oldest(), std::logic_error);
  // Five submitted, none taken: at most two kept besides the two in flight; the oldest is dropped.
  for (int k = 0; k < 5; ++k) renderer.submit(RendererKind::ssfr, view, pool->tank(), cameras[k]);
  EXPECT_EQ(renderer.frames_dropped(), 1u);
  EXPECT_EQ(renderer.frames_pending(), 4u);
  EXPECT_EQ(rgba(renderer.take_oldest()).pixels, expected[1].pixels);
}

// Frames read back as YCbCr 4:2:0 planes (converted on the GPU) make the JPEG that the RGBA
// frame makes through TurboJPEG's own conversion, to within rounding, at even and odd sizes, in
// 1.5 bytes a pixel plus row padding instead of 4.
TEST_F(RenderTest, PlanesFromTheGpuEncodeAsWellAsTheRgbaFrame) {
  auto pool = drop_of(3000);
  ParticleSource source(context());
  const ParticleView view = source.view_of(*pool);
  for (const auto& [width, height] : {std::pair{160u, 90u}, std::pair{101u, 57u}}) {
    for (const RendererKind kind : {RendererKind::points, RendererKind::ssfr}) {
      SCOPED_TRACE(std::to_string(width) + "×" + std::to_string(height) + ", " +
                   (kind == RendererKind::points ? "points" : "ssfr"));
      FrameRenderer renderer(context(), width, height);
      const OrbitCamera camera = camera_on(pool->tank(), 1.2f);
      const auto frame = rgba(renderer.render(kind, view, pool->tank(), camera));
      renderer.format = FrameRenderer::FrameFormat::yuv420;
      const auto planes =
          std::get<codec::ImageYuv420>(renderer.render(kind, view, pool->tank(), camera));
      ASSERT_EQ(planes.width, frame.width);
      ASSERT_EQ(planes.height, frame.height);
      EXPECT_LE(planes.bytes.size(), 1.5 * (width + 7) * (height + 1));
      const codec::JpegOptions q80{80, codec::ChromaSubsampling::s420};
      const auto from_rgba = codec::decode_jpeg(codec::encode_jpeg(frame, q80));
      const auto from_planes = codec::decode_jpeg(codec::encode_jpeg(planes, q80));
      const double rgba_db = codec::psnr(from_rgba, frame);
      const double planes_db = codec::psnr(from_planes, frame);
      std::printf("PSNR against the frame: %.2f dB through RGBA, %.2f dB through the planes\n",
                  rgba_db, planes_db);
      EXPECT_GT(planes_db, 25.0);  // small sprites at q80: about 28 dB either way
      EXPECT_NEAR(planes_db, rgba_db, 0.1);
    }
  }
}

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
  std::printf("rough pixels: %.1f %% by default, %.1f %% with half the depth range, %.1f %% "
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

// A device without independent blending (here: lavapipe with the feature left off) cannot draw
// SSFR or MC: asked for by name they are refused, naming the feature; drawable() and automatic
// fall back to points.
TEST(RendererFallback, WithoutIndependentBlendOnlyPointsAndTheRefusalNamesTheFeature) {
  gpu::ContextOptions options = gpu::options_from_environment();
  options.validation = true;
  options.independent_blend = false;
  options.log = [](const std::string&) {};
  gpu::Context context(options);
  const auto why = FrameRenderer::fluid_unsupported(context);
  ASSERT_TRUE(why.has_value());
  EXPECT_NE(why->find("independentBlend"), std::string::npos) << *why;
  sim::ParticleSet one;
  one.append({0.5f, 0.2f, 0.15f}, {0, 0, 0}, 0);
  ParticleSource source(context);
  const ParticleView view = source.upload(one, 0.02f);
  FrameRenderer renderer(context, 64, 48);
  for (RendererKind kind : {RendererKind::ssfr, RendererKind::mc, RendererKind::automatic}) {
    EXPECT_EQ(renderer.drawable(kind, 100000), RendererKind::points);
  }
  for (RendererKind kind : {RendererKind::ssfr, RendererKind::mc}) {
    try {
      renderer.render(kind, view, kTank, looking_at_tank());
      ADD_FAILURE() << "drew " << renderer_name(kind) << " without independent blending";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("independentBlend"), std::string::npos) << e.what();
    }
  }
  EXPECT_EQ(rgba(renderer.render(RendererKind::automatic, view, kTank, looking_at_tank())).pixels,
            rgba(renderer.render(RendererKind::points, view, kTank, looking_at_tank())).pixels);
  EXPECT_TRUE(context.validation_errors().empty());
  EXPECT_FALSE(FrameRenderer::fluid_unsupported(fluidcast::testing::test_context()).has_value());
}

TEST_F(RenderTest, MarchingCubesShowsTheFluidAtAnyResolutionAndAutoPicksByCount) {
  auto pool = drop_of(3000);
  ParticleSource source(context());
  const ParticleView view = source.view_of(*pool);
  FrameRenderer renderer(context(), 240, 135);
  const OrbitCamera camera = camera_on(pool->tank(), 2.0f);
  const auto empty = rgba(renderer.render(RendererKind::mc, {}, pool->tank(), camera));
  for (int resolution : {0, 40, 80, 128}) {  // 0: from the particle size
    renderer.mc.resolution = resolution;
    const auto image = rgba(renderer.render(RendererKind::mc, view, pool->tank(), camera));
    keep(image, "render_pool_mc_" + std::to_string(resolution));
    EXPECT_GT(pixels_differing(image, empty), 3000u) << resolution;
  }
  for (int resolution : {3, -1, 513}) {
    renderer.mc.resolution = resolution;
    EXPECT_THROW(renderer.render(RendererKind::mc, view, pool->tank(), camera),
                 std::invalid_argument)
        << resolution;
  }
  renderer.mc.resolution = 80;
  // 3000 particles are fewer than kMarchingCubesBelow: auto draws Marching Cubes.
  EXPECT_EQ(rgba(renderer.render(RendererKind::automatic, view, pool->tank(), camera)).pixels,
            rgba(renderer.render(RendererKind::mc, view, pool->tank(), camera)).pixels);
  EXPECT_EQ(resolve(RendererKind::automatic, kMarchingCubesBelow), RendererKind::ssfr);
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
  const auto centre_brightness = [&](int particles) {
    auto pool = drop_of(particles);
    OrbitCamera camera;
    camera.target = 0.5f * (pool->tank().min + pool->tank().max);
    camera.pitch_degrees = 89.0f;
    camera.distance = 0.6f;
    const auto image =
        rgba(renderer.render(RendererKind::ssfr, source.view_of(*pool), pool->tank(), camera));
    keep(image, "render_pool_from_above_" + std::to_string(particles));
    double sum = 0.0;
    for (int y = 40; y < 56; ++y)
      for (int x = 40; x < 56; ++x) sum += image.pixel(x, y)[0] + image.pixel(x, y)[1];
    return sum;
  };
  EXPECT_LT(centre_brightness(6000), 0.9 * centre_brightness(2000));
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

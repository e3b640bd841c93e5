// Offscreen rendering on lavapipe: sizes (1×1, odd, the device's maximum and one past it), bad
// cameras, an empty scene, a kept scene, particles where they project, the GPU solver's buffers
// read in place against an uploaded copy, frames in flight, YCbCr planes, the fallback without
// independent blending, Marching Cubes and each pass's GPU time. Frames are kept in
// build/test-output/ to look at.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <set>
#include <utility>
#include <variant>

#include "fluidcast/codec/jpeg.h"
#include "fluidcast/render/frame_renderer.h"
#include "fluidcast/render/particle_source.h"
#include "render_test_support.h"

namespace fluidcast::render {
namespace {

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

// The scene is drawn once per camera and kept for the frames after it: a kept scene must give the
// very image a fresh one does, in every mode, and a moved camera or another tank must not keep a
// stale one.
TEST_F(RenderTest, AKeptSceneGivesTheSameFrameAsAFreshOne) {
  auto pool = drop_of(1500);
  ParticleSource source(context());
  const ParticleView view = source.view_of(*pool);
  const OrbitCamera near = camera_on(pool->tank(), 2.0f);
  OrbitCamera turned = near;
  turned.yaw_degrees += 30.0f;
  for (auto kind : {RendererKind::ssfr, RendererKind::mc, RendererKind::points}) {
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

// A device without independent blending (here: lavapipe with the feature left off) cannot draw
// Marching Cubes: asked for by name it is refused, naming the feature; drawable() and automatic
// fall back to SSFR, which needs no blending (its particle pass is compute).
TEST(RendererFallback, WithoutIndependentBlendMarchingCubesGivesWayToSsfr) {
  gpu::ContextOptions options = gpu::options_from_environment();
  options.validation = true;
  options.independent_blend = false;
  options.log = [](const std::string&) {};
  gpu::Context context(options);
  const auto why = FrameRenderer::mc_unsupported(context);
  ASSERT_TRUE(why.has_value());
  EXPECT_NE(why->find("independentBlend"), std::string::npos) << *why;
  sim::ParticleSet one;
  one.append({0.5f, 0.2f, 0.15f}, {0, 0, 0}, 0);
  ParticleSource source(context);
  const ParticleView view = source.upload(one, 0.02f);
  FrameRenderer renderer(context, 64, 48);
  for (std::uint32_t particles : {1u, 100000u}) {
    for (RendererKind kind : {RendererKind::ssfr, RendererKind::mc, RendererKind::automatic}) {
      EXPECT_EQ(renderer.drawable(kind, particles), RendererKind::ssfr);
    }
  }
  try {
    renderer.render(RendererKind::mc, view, kTank, looking_at_tank());
    ADD_FAILURE() << "drew mc without independent blending";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("independentBlend"), std::string::npos) << e.what();
  }
  const auto ssfr = rgba(renderer.render(RendererKind::ssfr, view, kTank, looking_at_tank()));
  EXPECT_EQ(rgba(renderer.render(RendererKind::automatic, view, kTank, looking_at_tank())).pixels,
            ssfr.pixels);
  EXPECT_NE(ssfr.pixels,
            rgba(renderer.render(RendererKind::points, view, kTank, looking_at_tank())).pixels);
  EXPECT_TRUE(context.validation_errors().empty());
  EXPECT_FALSE(FrameRenderer::mc_unsupported(fluidcast::testing::test_context()).has_value());
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

// Each pass of a frame is timed as itself: the renderer's own passes have a time, the others none.
TEST_F(RenderTest, EachPassIsTimedAsItself) {
  if (!context().timestamps_supported()) GTEST_SKIP() << "the device has no timestamps";
  auto pool = drop_of(2000);
  ParticleSource source(context());
  const ParticleView view = source.view_of(*pool);
  FrameRenderer renderer(context(), 160, 90);
  renderer.ssfr.anisotropic = true;
  const OrbitCamera camera = camera_on(pool->tank(), 2.0f);
  const std::vector<std::pair<RendererKind, std::set<std::string_view>>> expected = {
      {RendererKind::points, {"scene_ms", "particles_ms", "readback_ms"}},
      {RendererKind::ssfr,
       {"scene_ms", "particles_ms", "smoothing_ms", "shading_ms", "readback_ms", "anisotropy_ms"}},
      {RendererKind::mc,
       {"scene_ms", "particles_ms", "smoothing_ms", "shading_ms", "readback_ms", "mc_field_ms",
        "mc_triangles_ms"}}};
  for (const auto& [kind, timed] : expected) {
    renderer.render(kind, view, pool->tank(), camera);
    const RenderTimes& times = renderer.last_times();
    for (const auto& [name, pass] : kRenderPasses) {
      if (timed.count(name)) {
        EXPECT_GT(times.*pass, 0.0) << renderer_name(kind) << ": " << name;
      } else {
        EXPECT_EQ(times.*pass, 0.0) << renderer_name(kind) << ": " << name;
      }
    }
  }
}

}  // namespace
}  // namespace fluidcast::render

// Offscreen rendering on lavapipe: sizes (1×1, odd, the device's maximum and one past it), an
// empty scene is only background, particles show where they project, and the GPU solver's
// buffers and a CPU solver's uploaded particles give the same picture.
#include <gtest/gtest.h>

#include <filesystem>

#include "fluidcast/codec/png.h"
#include "fluidcast/render/frame_renderer.h"
#include "fluidcast/render/particle_source.h"
#include "../unit/solver_test_support.h"
#include "gpu_test_support.h"

namespace fluidcast::render {
namespace {

using fluidcast::testing::GpuTest;

class RenderTest : public GpuTest {
 protected:
  static std::size_t pixels_unlike(const codec::ImageRgba& image, const glm::vec4& background) {
    std::size_t count = 0;
    for (std::size_t i = 0; i < image.pixels.size(); i += 4) {
      for (int c = 0; c < 3; ++c) {
        if (std::abs(int(image.pixels[i + c]) - int(std::lround(background[c] * 255))) > 2) {
          ++count;
          break;
        }
      }
    }
    return count;
  }
  // Keeps the image where a person can look at it: build/test-output/NAME.png.
  static void keep(const codec::ImageRgba& image, const std::string& name) {
    std::filesystem::create_directories("test-output");
    codec::write_png("test-output/" + name + ".png", image);
  }
};

TEST_F(RenderTest, EmptySceneIsOnlyBackground) {
  FrameRenderer renderer(context(), 64, 48);
  const codec::ImageRgba image = renderer.render({}, OrbitCamera{});
  EXPECT_EQ(image.width, 64);
  EXPECT_EQ(image.height, 48);
  EXPECT_EQ(pixels_unlike(image, renderer.background), 0u);
}

TEST_F(RenderTest, OneByOneOddAndLargestSizesAndBeyond) {
  for (auto [w, h] : {std::pair{1u, 1u}, {33u, 17u}}) {
    FrameRenderer renderer(context(), w, h);
    EXPECT_EQ(renderer.render({}, OrbitCamera{}).pixels.size(), std::size_t{w} * h * 4);
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
  OrbitCamera camera;
  camera.distance = std::numeric_limits<float>::quiet_NaN();
  EXPECT_THROW(renderer.render({}, camera), std::invalid_argument);
  camera = OrbitCamera{};
  camera.pitch_degrees = 95.0f;
  EXPECT_THROW(renderer.render({}, camera), std::invalid_argument);
}

TEST_F(RenderTest, ParticlesShowWhereTheyProject) {
  // One particle at the camera's target lands in the middle of the frame, and only there.
  sim::SceneParams scene;
  scene.kind = sim::SceneKind::drop;
  scene.particles = 500;
  auto solver = sim::make_cpu_solver(sim::SolverKind::pbf, sim::build_scene(scene), {});
  ParticleSource source(context());
  ParticleView view = source.view_of(*solver);
  ASSERT_EQ(view.count, 500u);
  FrameRenderer renderer(context(), 160, 120);
  OrbitCamera camera;
  const sim::ParticleSet particles = solver->snapshot();
  camera.target = particles.position[0];
  camera.distance = 0.5f;
  view.count = 1;
  view.radius = 0.02f;
  const codec::ImageRgba one = renderer.render(view, camera);
  keep(one, "render_one_particle");
  const std::uint8_t* centre = one.pixel(80, 60);
  EXPECT_GT(int(centre[0]) + centre[1] + centre[2], 100) << "the particle is not at the centre";
  const std::size_t lit = pixels_unlike(one, renderer.background);
  // A sphere of radius 2 cm at 0.5 m, 45° field of view: about 11 pixels across on 120 rows.
  EXPECT_GT(lit, 50u);
  EXPECT_LT(lit, 300u);
  EXPECT_EQ(pixels_unlike(renderer.render({}, camera), renderer.background), 0u);
}

TEST_F(RenderTest, GpuSolverBuffersInPlaceMatchTheUploadedCpuCopy) {
  sim::SceneParams scene;
  scene.particles = 2000;
  auto gpu_solver = sim::make_gpu_solver(sim::SolverKind::pbf, context(), sim::build_scene(scene), {});
  gpu_solver->step();
  ParticleSource source(context());
  FrameRenderer renderer(context(), 320, 180);
  OrbitCamera camera;
  const codec::ImageRgba in_place = renderer.render(source.view_of(*gpu_solver), camera);
  keep(in_place, "render_points_dam_break");
  EXPECT_GT(pixels_unlike(in_place, renderer.background), 2000u)
      << "the dam-break column is not in the frame";
  // The same particles through the upload path give the same picture, bit for bit.
  const codec::ImageRgba uploaded = renderer.render(
      source.upload(gpu_solver->snapshot(), gpu_solver->fluid().particle_radius()), camera);
  EXPECT_EQ(uploaded.pixels, in_place.pixels);
}

}  // namespace
}  // namespace fluidcast::render

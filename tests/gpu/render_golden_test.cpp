// Golden images: each renderer on a fixed scene (the drop scene as built, no simulation) and a
// fixed camera, against an accepted image in tests/golden/, within a PSNR tolerance (35 dB: the
// same driver gives identical images; another driver differs in rasterisation and rounding).
// A failing run writes the actual image to build/test-output/NAME_actual.png. To accept new
// images after a deliberate change, look at them, then run with FLUIDCAST_UPDATE_GOLDEN=1.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>

#include "fluidcast/codec/png.h"
#include "fluidcast/render/frame_renderer.h"
#include "fluidcast/render/particle_source.h"
#include "gpu_test_support.h"

namespace fluidcast::render {
namespace {

using testing::rgba;

class RenderGoldenTest : public fluidcast::testing::GpuTest,
                         public ::testing::WithParamInterface<RendererKind> {};

TEST_P(RenderGoldenTest, MatchesTheAcceptedImage) {
  sim::SceneParams scene;
  scene.kind = sim::SceneKind::drop;
  scene.particles = 2000;
  auto solver = sim::make_cpu_solver(sim::SolverKind::pbf, sim::build_scene(scene), {});
  ParticleSource source(context());
  FrameRenderer renderer(context(), 192, 108);
  renderer.ssfr = SsfrStyle{};  // with ellipsoids, as on a GPU, on every device
  OrbitCamera camera;
  camera.target = 0.5f * (solver->tank().min + solver->tank().max);
  camera.distance = 2.2f;
  camera.yaw_degrees = 20.0f;
  camera.pitch_degrees = 25.0f;
  const codec::ImageRgba actual =
      rgba(renderer.render(GetParam(), source.view_of(*solver), solver->tank(), camera));

  const std::string name = std::string(renderer_names()[static_cast<int>(GetParam())]) + "_drop";
  const std::filesystem::path golden =
      std::filesystem::path(FLUIDCAST_GOLDEN_DIR) / (name + ".png");
  if (const char* update = std::getenv("FLUIDCAST_UPDATE_GOLDEN"); update && *update == '1') {
    codec::write_png(golden, actual);
    GTEST_SKIP() << "accepted " << golden;
  }
  const codec::ImageRgba expected = codec::read_png(golden);
  const double db = codec::psnr(expected, actual);
  std::printf("%s: %.1f dB against %s\n", name.c_str(), db, golden.c_str());
  if (!(db >= 35.0)) {
    std::filesystem::create_directories("test-output");
    codec::write_png("test-output/" + name + "_actual.png", actual);
  }
  EXPECT_GE(db, 35.0);
}

INSTANTIATE_TEST_SUITE_P(EachRenderer, RenderGoldenTest,
                         ::testing::Values(RendererKind::points, RendererKind::ssfr,
                                           RendererKind::mc),
                         [](const ::testing::TestParamInfo<RendererKind>& param) {
                           return std::string(renderer_names()[static_cast<int>(param.param)]);
                         });

}  // namespace
}  // namespace fluidcast::render

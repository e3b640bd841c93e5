// What the rendering tests share: their fixture, the tank and cameras they look with, a pixel
// comparison, a small pool, and a place to keep frames for a person to look at
// (build/test-output/).
#pragma once

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>

#include "fluidcast/codec/png.h"
#include "fluidcast/render/frame_renderer.h"
#include "fluidcast/sim/solver.h"
#include "gpu_test_support.h"

namespace fluidcast::render {

using fluidcast::testing::rgba;

class RenderTest : public fluidcast::testing::GpuTest {};

inline const sim::Box kTank{{0, 0, 0}, {1.0f, 0.6f, 0.3f}};

inline OrbitCamera looking_at_tank() {
  OrbitCamera camera;
  camera.target = {0.5f, 0.2f, 0.15f};
  camera.distance = 1.6f;
  return camera;
}

// Pixels whose colour differs by more than 2 in some channel.
inline std::size_t pixels_differing(const codec::ImageRgba& a, const codec::ImageRgba& b) {
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
inline void keep(const codec::ImageRgba& image, const std::string& name) {
  std::filesystem::create_directories("test-output");
  codec::write_png("test-output/" + name + ".png", image);
}

// Looking at the middle of `tank` from `distance` metres.
inline OrbitCamera camera_on(const sim::Box& tank, float distance) {
  OrbitCamera camera;
  camera.target = 0.5f * (tank.min + tank.max);
  camera.distance = distance;
  return camera;
}

inline std::unique_ptr<sim::Solver> drop_of(int particles) {
  sim::SceneParams scene;
  scene.kind = sim::SceneKind::pool;
  scene.particles = particles;
  return sim::make_cpu_solver(sim::SolverKind::pbf, sim::build_scene(scene), {});
}

}  // namespace fluidcast::render

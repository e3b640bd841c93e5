// Rendering and encoding: GPU ms per pass (MC field and triangles, SSFR's anisotropy, scene,
// particles, smoothing, shading, read-back) from timestamps, frames/s with the read-back ring kept
// full, and JPEG encode ms (quality 80, 4:2:0, one thread) from RGBA and from the YCbCr planes the
// GPU converts (with their read-back: conversion and copy), throughput on the encoder pool (one
// thread per core) and its latency for one frame of planes (in strips on its threads), and the
// share of rough surface pixels (surface_roughness.h) in the last frame, at 640×360, 1280×720 and
// 1920×1080 with 64k and 1M particles (the dam break after a few GPU steps); Marching Cubes in a
// cubic 1 m tank on a 128³ grid (the target), and as the client's local mode draws it (5000
// particles, 640×360, grid from the particle size); SSFR with spheres instead of ellipsoids at
// 1920×1080 (SsfrSpheres); what a new renderer costs the thread that makes it, as a new viewer or a
// resize does (NewRenderer*). `--smoke` runs small cases (for CI, on lavapipe); `--device N` picks
// the device.
#include <benchmark/benchmark.h>

#include <chrono>
#include <memory>
#include <string>
#include <vector>

#include "bench_main.h"
#include "fluidcast/codec/jpeg.h"
#include "fluidcast/codec/jpeg_encoder_pool.h"
#include "fluidcast/gpu/context.h"
#include "fluidcast/render/frame_renderer.h"
#include "fluidcast/render/particle_source.h"
#include "fluidcast/render/surface_roughness.h"
#include "fluidcast/sim/solver.h"

namespace {

using namespace fluidcast;
using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// SSFR draws ellipsoids by default; `spheres` turns the anisotropy off (the cost it adds).
enum class Particles { as_styled, spheres };

void measure_encoding(benchmark::State& state, render::FrameRenderer& renderer,
                      render::RendererKind kind, const render::ParticleView& view,
                      const sim::Box& tank, const render::OrbitCamera& camera,
                      const codec::Image& last);

// The dam break of range(2) particles (range(4): in a unit cube, so the grid is range(3)³), ten
// steps in, on the GPU.
std::unique_ptr<sim::Solver> fluid_for(const benchmark::State& state) {
  sim::SceneParams scene;
  scene.particles = static_cast<int>(state.range(2));
  if (state.range(4) != 0) scene.tank_length = scene.tank_height = scene.depth = 1.0f;
  sim::SolverParams params;
  params.max_particles = std::max(params.max_particles, scene.particles);
  auto solver = sim::make_gpu_solver(sim::SolverKind::pbf, bench::gpu_context(),
                                     sim::build_scene(scene), params);
  for (int k = 0; k < 10; ++k) solver->step();
  return solver;
}

void run_render(benchmark::State& state, render::RendererKind kind, int frames_per_iteration,
                Particles particles) {
  const auto width = static_cast<std::uint32_t>(state.range(0));
  const auto height = static_cast<std::uint32_t>(state.range(1));
  const int mc_nodes = static_cast<int>(state.range(3));
  const auto solver = fluid_for(state);
  render::ParticleSource source(bench::gpu_context());
  const render::ParticleView view = source.view_of(*solver);
  render::FrameRenderer renderer(bench::gpu_context(), width, height);
  renderer.mc.resolution = mc_nodes;
  renderer.ssfr.anisotropic = particles == Particles::as_styled;
  render::OrbitCamera camera;
  camera.target = 0.5f * (solver->tank().min + solver->tank().max);
  camera.distance = 1.3f * glm::length(solver->tank().size());
  codec::Image last = renderer.render(kind, view, solver->tank(), camera);  // warm-up

  render::RenderTimes sum;
  std::uint64_t frames = 0;
  double seconds = 0.0;
  for (auto _ : state) {
    const auto start = Clock::now();
    for (int k = 0; k < frames_per_iteration; ++k) {
      renderer.submit(kind, view, solver->tank(), camera);
      if (renderer.frames_pending() >= render::FrameRenderer::kFramesInFlight) {
        last = renderer.take_oldest();
        for (const auto& [name, pass] : render::kRenderPasses) {
          sum.*pass += renderer.last_times().*pass;
        }
        ++frames;
      }
    }
    while (renderer.frames_pending() > 0) {
      last = renderer.take_oldest();
      ++frames;
    }
    const double elapsed = seconds_since(start);
    state.SetIterationTime(elapsed);
    seconds += elapsed;
  }
  const double timed = static_cast<double>(std::max<std::uint64_t>(frames, 1));
  state.counters["frames_per_s"] = static_cast<double>(frames) / seconds;
  for (const auto& [name, pass] : render::kRenderPasses) {
    const bool mc_only = name.starts_with("mc_");
    if (!mc_only || kind == render::RendererKind::mc) {
      state.counters[std::string(name)] = sum.*pass / timed;
    }
  }
  if (kind != render::RendererKind::points) {
    state.counters["rough_share"] =
        render::measure_roughness(renderer.surface_distances(), width, height,
                                  camera.projection(float(width) / float(height)))
            .rough_share;
  }
  measure_encoding(state, renderer, kind, view, solver->tank(), camera, last);
}

// Encoding the frame just rendered: one thread, then the pool at one thread per core; and the same
// frame read back as YCbCr 4:2:0 planes (as the server streams), which the encoder only
// compresses.
void measure_encoding(benchmark::State& state, render::FrameRenderer& renderer,
                      render::RendererKind kind, const render::ParticleView& view,
                      const sim::Box& tank, const render::OrbitCamera& camera,
                      const codec::Image& last) {
  const codec::JpegOptions jpeg{80, codec::ChromaSubsampling::s420};
  const int encodes = 10;
  auto start = Clock::now();
  std::size_t bytes = 0;
  for (int k = 0; k < encodes; ++k) bytes = codec::encode_jpeg(last, jpeg).size();
  state.counters["encode_ms"] = 1e3 * seconds_since(start) / encodes;
  state.counters["jpeg_kib"] = static_cast<double>(bytes) / 1024.0;
  renderer.format = render::FrameRenderer::FrameFormat::yuv420;
  const codec::Image planes = renderer.render(kind, view, tank, camera);
  state.counters["planes_readback_ms"] = renderer.last_times().readback_ms;
  start = Clock::now();
  for (int k = 0; k < encodes; ++k) bytes = codec::encode_jpeg(planes, jpeg).size();
  state.counters["planes_encode_ms"] = 1e3 * seconds_since(start) / encodes;
  codec::JpegEncoderPool pool;
  std::vector<std::future<std::vector<std::uint8_t>>> jobs;
  start = Clock::now();
  for (unsigned k = 0; k < 4 * pool.threads(); ++k) jobs.push_back(pool.encode(last, jpeg));
  for (auto& job : jobs) job.get();
  state.counters["pool_encodes_per_s"] = static_cast<double>(jobs.size()) / seconds_since(start);
  // The server's path: the planes through the idle pool, one frame at a time, in strips on its
  // threads where the frame is tall enough (jpeg_strips.h): a frame's encode latency.
  start = Clock::now();
  for (int k = 0; k < encodes; ++k) pool.encode(planes, jpeg).get();
  state.counters["pool_planes_encode_ms"] = 1e3 * seconds_since(start) / encodes;
}

// What a new viewer or a resize costs the thread that makes its renderer (the server's worker):
// constructing the FrameRenderer, then its first frame (where each kind builds what it draws
// with) and a warm frame after it, all in wall time around the calls, the frame waited for.
void run_new_renderer(benchmark::State& state, render::RendererKind kind) {
  const auto width = static_cast<std::uint32_t>(state.range(0));
  const auto height = static_cast<std::uint32_t>(state.range(1));
  const auto solver = fluid_for(state);
  render::ParticleSource source(bench::gpu_context());
  const render::ParticleView view = source.view_of(*solver);
  render::OrbitCamera camera;
  camera.target = 0.5f * (solver->tank().min + solver->tank().max);
  camera.distance = 1.3f * glm::length(solver->tank().size());
  // Another viewer's, as a server has beside a new one: what renderers share stays made.
  const render::FrameRenderer beside(bench::gpu_context(), 16, 16);
  double construct = 0.0, first = 0.0, warm = 0.0;
  int made = 0;
  for (auto _ : state) {
    auto start = Clock::now();
    render::FrameRenderer renderer(bench::gpu_context(), width, height);
    const double constructing = seconds_since(start);
    start = Clock::now();
    renderer.render(kind, view, solver->tank(), camera);
    const double first_frame = seconds_since(start);
    start = Clock::now();
    renderer.render(kind, view, solver->tank(), camera);
    warm += seconds_since(start);
    construct += constructing;
    first += first_frame;
    state.SetIterationTime(constructing + first_frame);
    ++made;
  }
  state.counters["construct_ms"] = 1e3 * construct / made;
  state.counters["first_frame_ms"] = 1e3 * first / made;
  state.counters["warm_frame_ms"] = 1e3 * warm / made;
}

enum class Tank { dam_break, cube };

void add(const char* name, render::RendererKind kind, int width, int height, int particles,
         int frames, int mc_nodes = 0, Tank tank = Tank::dam_break,
         Particles shape = Particles::as_styled) {
  benchmark::RegisterBenchmark(name, run_render, kind, frames, shape)
      ->Args({width, height, particles, mc_nodes, tank == Tank::cube ? 1 : 0})
      ->ArgNames({"width", "height", "particles", "mc_nodes", "cube"})
      ->Iterations(1)
      ->UseManualTime()
      ->Unit(benchmark::kMillisecond);
}

void add_new_renderer(const char* name, render::RendererKind kind, int width, int height,
                      int particles) {
  benchmark::RegisterBenchmark(name, run_new_renderer, kind)
      ->Args({width, height, particles, 0, 0})
      ->ArgNames({"width", "height", "particles", "mc_nodes", "cube"})
      ->Iterations(5)
      ->UseManualTime()
      ->Unit(benchmark::kMillisecond);
}

void register_cases(bool smoke) {
  for (auto [name, kind] : {std::pair{"NewRendererSsfr", render::RendererKind::ssfr},
                            {"NewRendererMc", render::RendererKind::mc},
                            {"NewRendererPoints", render::RendererKind::points}}) {
    add_new_renderer(name, kind, smoke ? 320 : 1280, smoke ? 180 : 720, 4000);
  }
  if (smoke) {
    add("Ssfr", render::RendererKind::ssfr, 320, 180, 4000, 3);
    add("Points", render::RendererKind::points, 320, 180, 4000, 3);
    add("Mc", render::RendererKind::mc, 320, 180, 4000, 3, 48, Tank::cube);
    add("Mc", render::RendererKind::mc, 640, 360, 5000, 10);  // the client's local mode
    return;
  }
  for (int particles : {64000, 1000000}) {
    add("Mc", render::RendererKind::mc, 1920, 1080, particles, 100, 128, Tank::cube);
  }
  add("Mc", render::RendererKind::mc, 640, 360, 5000, 100);
  for (int particles : {64000, 1000000}) {
    for (auto [w, h] : {std::pair{640, 360}, {1280, 720}, {1920, 1080}}) {
      add("Ssfr", render::RendererKind::ssfr, w, h, particles, 100);
      add("Points", render::RendererKind::points, w, h, particles, 100);
    }
    add("SsfrSpheres", render::RendererKind::ssfr, 1920, 1080, particles, 100, 0, Tank::dam_break,
        Particles::spheres);
  }
}

}  // namespace

int main(int argc, char** argv) { return bench::run_gpu_benchmarks(argc, argv, register_cases); }

// Renders frames offscreen and reads them back: the particles are read where they are (the GPU
// solver's buffers, or a ParticleUpload of a CPU solver's), nothing else crosses to the GPU.
// Three modes: points (diagnosis), SSFR and Marching Cubes. The ray-cast scene around the fluid
// is drawn again only when the camera or the tank changes.
#pragma once

#include <array>
#include <deque>
#include <glm/glm.hpp>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "fluidcast/codec/image.h"
#include "fluidcast/gpu/buffer.h"
#include "fluidcast/gpu/command_slot.h"
#include "fluidcast/render/camera.h"
#include "fluidcast/render/render_target.h"
#include "fluidcast/sim/particles.h"
#include "fluidcast/sim/statistics.h"

namespace fluidcast::render {

class Anisotropy;
class FluidTarget;
class GraphicsPipeline;
struct ScreenPipelines;
class MarchingCubes;
struct SplatConstants;
enum class SplatMode : std::uint32_t;
struct FrameParams;

// automatic: Marching Cubes below kMarchingCubesBelow particles, SSFR from there (the talk's rule:
// MC for small counts and near views, SSFR for large counts and far views).
enum class RendererKind { points, ssfr, mc, automatic };
inline constexpr std::uint32_t kMarchingCubesBelow = 5000;
const std::vector<std::string_view>& renderer_names();
std::string_view renderer_name(RendererKind kind);
RendererKind parse_renderer(std::string_view name);  // throws std::invalid_argument listing them

// The renderer `kind` means for this many particles (resolves automatic).
RendererKind resolve(RendererKind kind, std::uint32_t particles);

// Where the particles are on the GPU: vec4 positions and velocities (w unused). Taken afresh for
// each frame (ParticleSource::view_of) and recorded at once: when a solver or an upload replaces
// the buffers behind it, the old ones are retired to the context, not destroyed, so frames already
// submitted read them to the end; no caller waits for the GPU to keep them alive.
struct ParticleView {
  VkDeviceAddress position = 0;
  VkDeviceAddress velocity = 0;
  VkDeviceAddress density_ratio = 0;  // float ρ/ρ0, or 0 where there is none
  std::uint32_t count = 0;
  float radius = 0.01f;  // m
};

struct PointsStyle {
  enum class ColourBy { speed, density };
  ColourBy colour_by = ColourBy::speed;
  float density_span = 0.05f;  // ρ/ρ0 from 1 − span (slow colour) to 1 + span (fast colour)
  glm::vec3 slow_colour{0.10f, 0.35f, 0.85f};
  glm::vec3 fast_colour{0.90f, 0.95f, 1.00f};
  float full_speed = 2.0f;  // m/s that get fast_colour
};

struct SsfrStyle {
  // bilateral: van der Laan et al. (2009); narrow_range: Truong & Yuksel (2018) — a narrow,
  // growing depth range with symmetric pairs, which keeps separate surfaces apart and rounds
  // silhouettes off (shaders/render/ssfr_smooth.comp says how).
  enum class DepthFilter { bilateral, narrow_range };
  DepthFilter filter = DepthFilter::narrow_range;  // smoother and fewer streaks (docs/images)
  // Of the depth filter, in particle radii (a length in the scene: view-invariant).
  float smoothing_radii = 4.0f;
  // Rounds of the separable filter (x then y): more is smoother and costs more.
  int smoothing_passes = 2;
  // Depth difference, in particle radii, that the filter treats as a different surface (bilateral:
  // the range weight's scale; narrow range: the range's initial half-width and its growth per
  // accepted sample). Narrower keeps more of each sphere's bump: at 2 radii a splashing 8000-
  // particle dam break left 32 % of its surface pixels turned over 20° from their neighbours
  // (specular speckle), at 4 radii 6 % (surface_roughness.h; docs/images/ssfr-surface-*).
  // Range 0.5–20.
  float depth_falloff_radii = 4.0f;
  // Anisotropic kernels (Yu & Turk 2013): each particle drawn as an ellipsoid shaped by its
  // neighbours, flat along the surface, so the surface is a sheet before any filtering; else
  // spheres of the particle's radius. Costs a grid and a pass over the particles each frame
  // (RenderTimes::anisotropy_ms). A FrameRenderer on a CPU device (lavapipe) starts with it off.
  bool anisotropic = true;
  // Of an ellipsoid, the longest axis over the shortest, at most: 1 to 16 (1: spheres, still at
  // the smoothed centres). Yu & Turk's 4.
  float max_stretch = 4.0f;
  // How far each centre moves to the weighted mean of its neighbours, 0 to 1 (Yu & Turk's λ):
  // pulls lone bumps into the surface.
  float centre_smoothing = 0.9f;
  // Anisotropic only: a particle with fewer neighbours than this within two particle spacings
  // (about 33 inside the fluid) is spray, drawn white and matte over the water instead of as a
  // bead of its surface with its own highlight. 0 to 32 (0: none); by default the statistics'
  // rule (sim::kSprayNeighbours).
  int spray_neighbours = sim::kSprayNeighbours;
  // Beer–Lambert absorption per metre of water: red goes first, so thick water turns blue-green.
  glm::vec3 absorption{6.0f, 1.8f, 0.9f};
};

// GPU milliseconds of one frame's passes, from timestamps (0 where the device has none).
struct RenderTimes {
  double scene_ms = 0;         // the ray-cast tank, floor and sky, and its copy (near 0 while the
                               // camera stays)
  double particles_ms = 0;     // points: the spheres; SSFR: surface depth, thickness and spray
  double smoothing_ms = 0;     // SSFR: the depth filter passes
  double shading_ms = 0;       // SSFR: normals and shading
  double readback_ms = 0;      // the finished frame to host-visible memory (and to YCbCr planes)
  double anisotropy_ms = 0;    // SSFR: the grid over the particles and their ellipsoids
  double mc_field_ms = 0;      // MC: the scalar field splatted from the particles
  double mc_triangles_ms = 0;  // MC: triangles and normals from the tables

  double drawing_ms() const;  // every pass of kRenderPasses but the read-back
};

// Each pass by the name benchmarks report it under, with its field.
inline constexpr std::array<std::pair<std::string_view, double RenderTimes::*>, 8> kRenderPasses{{
    {"scene_ms", &RenderTimes::scene_ms},
    {"particles_ms", &RenderTimes::particles_ms},
    {"smoothing_ms", &RenderTimes::smoothing_ms},
    {"shading_ms", &RenderTimes::shading_ms},
    {"readback_ms", &RenderTimes::readback_ms},
    {"anisotropy_ms", &RenderTimes::anisotropy_ms},
    {"mc_field_ms", &RenderTimes::mc_field_ms},
    {"mc_triangles_ms", &RenderTimes::mc_triangles_ms},
}};

struct McStyle {
  // Grid nodes along the tank's longest side, 4 to 512 (the talk: 80×40×40); 0: from the
  // particles' size, a node per particle spacing (finer adds cost, not detail: the field is a
  // blur of about a particle's width).
  int resolution = 0;
  float threshold = 0.5f;    // the surface: where the field is this fraction of fluid at rest
  int smoothing_passes = 1;  // of the depth filter before shading (the mesh is smooth already)
  // Of that filter, in particle radii: it only has to hide the facets, a node or so wide.
  float smoothing_radii = 2.0f;
};

class FrameRenderer {
 public:
  // Throws std::invalid_argument for a size of zero or beyond the device's limits.
  FrameRenderer(gpu::Context& context, std::uint32_t width, std::uint32_t height);
  ~FrameRenderer();

  // Why the device cannot draw Marching Cubes (a sentence naming the missing feature); nothing
  // when it can. Points and SSFR it always can.
  static std::optional<std::string> mc_unsupported(const gpu::Context& context);
  // What `kind` draws for this many particles on this device: automatic resolved, and SSFR in
  // place of Marching Cubes where the device cannot draw that.
  RendererKind drawable(RendererKind kind, std::uint32_t particles) const;

  PointsStyle points;
  SsfrStyle ssfr;
  McStyle mc;
  // A point of the frame, normalised (0 to 1 from the top-left), where the next frames also read
  // back the fluid's surface: where a finger touches the fluid (SSFR and MC; not points).
  std::optional<glm::vec2> probe;

  // What frames come back as: RGBA, or the YCbCr 4:2:0 planes a JPEG holds, converted on the GPU
  // (1.5 bytes a pixel to read back instead of 4, and no colour conversion left to the encoder).
  enum class FrameFormat { rgba, yuv420 };
  FrameFormat format = FrameFormat::rgba;

  // A ring of read-back slots: frame N is copied to the host while frame N+1 renders.
  static constexpr std::size_t kFramesInFlight = 2;

  // Records and submits one frame of the particles in `tank` (automatic: as drawable() says);
  // returns its number at once. With
  // kFramesInFlight frames already in flight, first waits for the oldest and keeps its image for
  // take_oldest(); of kept images beyond kFramesInFlight, the oldest are dropped (counted).
  // Throws std::invalid_argument for a camera that is not finite or out of range, and for a
  // renderer the device cannot draw (mc_unsupported says why).
  std::uint64_t submit(RendererKind kind, const ParticleView& particles, const sim::Box& tank,
                       const OrbitCamera& camera);
  // The oldest frame submitted and not yet taken, in the format it was submitted with, waiting
  // for it if need be. Throws std::logic_error when there is none.
  codec::Image take_oldest();
  std::size_t frames_pending() const;
  // Whether take_oldest() would return without waiting.
  bool oldest_finished();
  std::uint64_t frames_dropped() const { return dropped_; }
  // The passes of the frame most recently taken or kept.
  const RenderTimes& last_times() const { return last_times_; }
  // Where, in the scene, that frame's probe met the fluid's (smoothed) surface; nothing when it
  // had no probe, drew points, or the probe missed the fluid.
  std::optional<glm::vec3> last_probe_hit() const { return last_probe_hit_; }

  // The view distance per pixel of the newest frame submitted, after smoothing (+inf where there
  // is no fluid; SSFR and MC), once the GPU has drawn it: what the shading took its normals
  // from, for measuring the surface (surface_roughness.h).
  std::vector<float> surface_distances() const;

  // submit() then take_oldest(): one frame, waited for.
  codec::Image render(RendererKind kind, const ParticleView& particles, const sim::Box& tank,
                      const OrbitCamera& camera);

 private:
  struct Slot {
    explicit Slot(gpu::Context& context, std::uint64_t bytes);
    gpu::Buffer readback;
    gpu::TimestampQueries timestamps;
    // Last, so that it is destroyed first: its destructor waits for the frame that uses the rest.
    gpu::CommandSlot commands;
    bool in_flight = false;
    std::uint64_t frame = 0;
    std::optional<glm::vec2> probe;  // where this frame read the surface back, if it did
    FrameFormat format = FrameFormat::rgba;
    glm::mat4 view{1.0f}, projection{1.0f};
    // Each timestamp after the first ends a pass: the field of RenderTimes it times, its index.
    std::vector<std::pair<double RenderTimes::*, std::uint32_t>> timed;
    void mark(VkCommandBuffer recording, double RenderTimes::*pass);
  };
  struct SceneKey {
    glm::mat4 view, projection;
    glm::vec3 tank_min, tank_max;
    bool operator==(const SceneKey&) const = default;
  };
  FrameParams frame_params(RendererKind kind, const ParticleView& particles, const sim::Box& tank,
                           const OrbitCamera& camera) const;
  void record(VkCommandBuffer commands, RendererKind kind, const ParticleView& particles,
              const sim::Box& tank, const OrbitCamera& camera, Slot& slot);
  // What the particle passes splat: the particles, or SSFR's ellipsoids (centres and shapes).
  struct ParticleShapes {
    VkDeviceAddress position, velocity, density_ratio, shape;
    bool ellipsoids;
  };
  // The shapes the fluid is drawn from: for MC its mesh (marching_cubes_), for SSFR with
  // anisotropy the ellipsoids.
  ParticleShapes record_shapes(VkCommandBuffer commands, RendererKind kind,
                               const ParticleView& particles, const sim::Box& tank, Slot& slot);
  // The scene into scene_, unless it holds this one already.
  void record_scene(VkCommandBuffer commands, const SceneKey& scene, Slot& slot);
  SplatConstants splat_constants(const ParticleShapes& shapes, std::uint32_t particles,
                                 SplatMode mode) const;
  // One particle pass (particle_splat.comp), the queue of large particles included.
  void record_particle_pass(VkCommandBuffer commands, const SplatConstants& splat) const;
  // SSFR: the particles' ellipsoids into the surface buffers (depth_, thickness_, spray_).
  void record_ssfr_particles(VkCommandBuffer commands, const ParticleShapes& shapes,
                             std::uint32_t particles);
  // Points: the scene, and the particles over it, into image_.
  void record_points(VkCommandBuffer commands, const ParticleShapes& shapes,
                     std::uint32_t particles);
  // SSFR and MC: the depth filter and the shading into image_.
  void record_fluid_screen(VkCommandBuffer commands, RendererKind kind, Slot& slot);
  // image_ into the slot's read-back, and the probe's distance after it.
  void record_read_back(VkCommandBuffer commands, const Slot& slot);
  // Converts image_ into planes_ and copies those to the slot's read-back.
  void record_yuv420_read_back(VkCommandBuffer commands, const Slot& slot);
  std::uint64_t frame_bytes(FrameFormat format) const;  // in a read-back, before the probe
  codec::Image collect(Slot& slot);
  Slot* oldest_in_flight();  // of the frames not yet collected; null when none

  gpu::Context* context_;
  RenderTarget target_;
  std::unique_ptr<GraphicsPipeline> background_;
  // Marching Cubes' mesh: none where the device cannot blend float attachments.
  std::unique_ptr<FluidTarget> fluid_target_;
  std::unique_ptr<GraphicsPipeline> mc_surface_;
  std::unique_ptr<MarchingCubes> marching_cubes_;     // built for the tank of the first mc frame
  std::unique_ptr<Anisotropy> anisotropy_;            // made for the first anisotropic frame
  std::shared_ptr<const ScreenPipelines> pipelines_;  // the device's, shared
  gpu::Buffer frame_params_;
  // The particle passes' queue: the dispatch of particle_splat_large.comp and the particles it
  // casts.
  gpu::Buffer splat_queue_;
  // One value per pixel: the nearest particle's or surface's distance (and a filtered copy),
  // thickness and spray (SSFR and MC), the scene, and the finished frame.
  gpu::Buffer depth_, depth_scratch_, thickness_, spray_, scene_, image_;
  gpu::Buffer planes_;  // the finished frame as YCbCr 4:2:0 (codec::ImageYuv420's layout)
  std::vector<Slot> slots_;
  // The camera and tank whose scene scene_ holds, if it holds one.
  std::optional<SceneKey> scene_drawn_for_;
  std::uint64_t next_frame_ = 0;
  std::deque<codec::Image> kept_;  // finished frames collected early, oldest first
  std::uint64_t dropped_ = 0;
  RenderTimes last_times_;
  std::optional<glm::vec3> last_probe_hit_;
};

}  // namespace fluidcast::render

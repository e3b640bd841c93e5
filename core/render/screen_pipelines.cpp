#include "screen_pipelines.h"

#include <map>
#include <mutex>

#include "fluidcast_shaders/fluidcast_render.h"
#include "frame_params.h"

namespace fluidcast::render {
namespace {

constexpr std::uint32_t kScreenGroup = 64;

}  // namespace

ScreenPipelines::ScreenPipelines(gpu::Context& context)
    : splat(context, shaders::render_particle_splat_comp, sizeof(SplatConstants), kScreenGroup),
      splat_large(context, shaders::render_particle_splat_large_comp, sizeof(SplatConstants),
                  kScreenGroup),
      splat_resolve(context, shaders::render_ssfr_resolve_comp, sizeof(SplatConstants),
                    kScreenGroup),
      smooth(context, shaders::render_ssfr_smooth_comp, sizeof(ScreenConstants), kScreenGroup),
      shade(context, shaders::render_ssfr_shade_comp, sizeof(ScreenConstants), kScreenGroup),
      yuv420(context, shaders::render_yuv420_comp, sizeof(YuvConstants), kScreenGroup) {}

std::shared_ptr<const ScreenPipelines> ScreenPipelines::shared(gpu::Context& context) {
  static std::mutex mutex;
  static std::map<const gpu::Context*, std::weak_ptr<const ScreenPipelines>> sets;
  const std::lock_guard lock(mutex);
  std::erase_if(sets, [](const auto& entry) { return entry.second.expired(); });
  std::weak_ptr<const ScreenPipelines>& kept = sets[&context];
  if (auto set = kept.lock()) return set;
  auto set = std::make_shared<const ScreenPipelines>(context);
  kept = set;
  return set;
}

}  // namespace fluidcast::render

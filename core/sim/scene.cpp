#include "fluidcast/sim/scene.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>

namespace fluidcast::sim {
namespace {

constexpr float kPi = std::numbers::pi_v<float>;

float volume(const Box& box) {
  const glm::vec3 s = box.size();
  return s.x * s.y * s.z;
}

// Fills `count` sites of a lattice that spans the block exactly in x and z, layer by layer from
// the bottom, so a block holds an exact count and its top layer may be partly filled. The x and z
// spacings are the block's size over a whole number of sites nearest to d; the y spacing keeps
// the volume per particle d³, so the water's volume — and its mass — is what was asked. A partly
// filled top layer is spread evenly over as many rows as it can fill, and evenly along each row:
// filled from one corner, it held its water to one side, and a pool started with a wave (1000
// particles: 0.38 of a layer, the centre of mass 5 and 6 mm off the middle in x and z, sloshing
// for seconds).
void fill_block(const Box& block, float d, int count, ParticleSet& out) {
  const glm::vec3 size = block.size();
  const int nx = std::max(1, static_cast<int>(std::lround(size.x / d)));
  const int nz = std::max(1, static_cast<int>(std::lround(size.z / d)));
  const float dx = size.x / static_cast<float>(nx), dz = size.z / static_cast<float>(nz);
  const float dy = d * d * d / (dx * dz);
  const auto place = [&](int x, int layer, int z) {
    const glm::vec3 p{block.min.x + (static_cast<float>(x) + 0.5f) * dx,
                      block.min.y + (static_cast<float>(layer) + 0.5f) * dy,
                      block.min.z + (static_cast<float>(z) + 0.5f) * dz};
    out.append(p, glm::vec3(0.0f), static_cast<std::uint32_t>(out.size()));
  };
  const int per_layer = nx * nz;
  const int full_layers = count / per_layer;
  for (int layer = 0; layer < full_layers; ++layer)
    for (int z = 0; z < nz; ++z)
      for (int x = 0; x < nx; ++x) place(x, layer, z);
  // Rows and sites within a row at the middles of equal shares: (2i + 1) n / 2m of m in n.
  // In 64 bits: a 100 × 100 m floor takes a top layer of up to 10⁷ sites in 5000 rows.
  const auto spread = [](std::int64_t i, std::int64_t m, std::int64_t n) {
    return static_cast<int>((2 * i + 1) * n / (2 * m));
  };
  const std::int64_t on_top = count % per_layer;
  const std::int64_t rows = std::min<std::int64_t>(nz, on_top);
  for (std::int64_t row = 0; row < rows; ++row) {
    const std::int64_t in_row = on_top * (row + 1) / rows - on_top * row / rows;
    for (std::int64_t i = 0; i < in_row; ++i)
      place(spread(i, in_row, nx), full_layers, spread(row, rows, nz));
  }
}

// A particle spacing is at most this share of the tank's thinnest side.
constexpr float kWidestSpacingOfThinnestSide = 0.5f;

void fill_blocks(const std::vector<Box>& blocks, float d, int total, ParticleSet& out) {
  float total_volume = 0.0f;
  for (const Box& b : blocks) total_volume += volume(b);
  int placed = 0;
  for (std::size_t i = 0; i < blocks.size(); ++i) {
    const int share = i + 1 == blocks.size()
                          ? total - placed
                          : static_cast<int>(std::lround(total * volume(blocks[i]) / total_volume));
    fill_block(blocks[i], d, share, out);
    placed += share;
  }
}

}  // namespace

const std::vector<std::string_view>& scene_names() {
  static const std::vector<std::string_view> names = {"dam_break", "double_dam_break", "drop",
                                                      "pool"};
  return names;
}

std::string_view to_string(SceneKind kind) { return scene_names()[static_cast<int>(kind)]; }

SceneKind parse_scene(std::string_view name) {
  return static_cast<SceneKind>(index_of_name(scene_names(), name, "scene", "scene"));
}

const std::vector<ParamSpec<SceneParams>>& scene_param_specs() {
  using S = SceneParams;
  static const std::vector<ParamSpec<S>> specs = {
      {"particles", "1", "Number of particles of the scene", &S::particles, 1, kMostParticles},
      {"tank-length", "m", "Inner length of the tank (x)", &S::tank_length, 0.05, 100},
      {"tank-height", "m", "Inner height of the tank (y): the lid", &S::tank_height, 0.05, 100},
      {"depth", "m", "Inner depth of the tank (z); dam-break columns fill all of it", &S::depth,
       0.01, 100},
      {"column-width", "m", "Dam break: width of the water column (x)", &S::column_width, 0.01,
       100},
      {"column-height", "m", "Dam break: height of the water column (y)", &S::column_height, 0.01,
       100},
      {"pool-height", "m", "Pool and drop: height of the resting water", &S::pool_height, 0.01,
       100},
      {"drop-radius", "m", "Drop: radius of the falling ball of water", &S::drop_radius, 0.01, 100},
      {"drop-height", "m", "Drop: height of the ball's centre above the floor", &S::drop_height,
       0.01, 100},
  };
  return specs;
}

void validate(const SceneParams& p) {
  validate(p, scene_param_specs());
  auto require = [](bool ok, const std::string& message) {
    if (!ok) throw ParamError(message);
  };
  switch (p.kind) {
    case SceneKind::dam_break:
      require(p.column_width < p.tank_length, "{column-width}: must be less than {tank-length}");
      require(p.column_height <= p.tank_height, "{column-height}: must not exceed {tank-height}");
      break;
    case SceneKind::double_dam_break:
      require(2 * p.column_width < p.tank_length,
              "{column-width}: two columns must fit in {tank-length}");
      require(p.column_height <= p.tank_height, "{column-height}: must not exceed {tank-height}");
      break;
    case SceneKind::drop:
      require(p.drop_height - p.drop_radius > p.pool_height,
              "{drop-height}: the ball must start above the pool (drop-height − drop-radius > "
              "pool-height)");
      require(p.drop_height + p.drop_radius <= p.tank_height,
              "{drop-height}: the ball must fit under {tank-height}");
      require(2 * p.drop_radius <= std::min(p.tank_length, p.depth),
              "{drop-radius}: the ball must fit in the tank's length and depth");
      [[fallthrough]];
    case SceneKind::pool:
      require(p.pool_height < p.tank_height, "{pool-height}: must be less than {tank-height}");
      break;
  }
}

Scene build_scene(const SceneParams& params) {
  validate(params);
  Scene scene;
  scene.params = params;
  scene.tank =
      Box{glm::vec3(0.0f), glm::vec3(params.tank_length, params.tank_height, params.depth)};
  const float L = params.tank_length, D = params.depth;
  const int n = params.particles;

  auto column = [&](float x0, float x1) {
    return Box{{x0, 0.0f, 0.0f}, {x1, params.column_height, D}};
  };
  std::vector<Box> blocks;
  float water_volume = 0.0f;
  switch (params.kind) {
    case SceneKind::dam_break:
      blocks = {column(0.0f, params.column_width)};
      break;
    case SceneKind::double_dam_break:
      blocks = {column(0.0f, params.column_width), column(L - params.column_width, L)};
      break;
    case SceneKind::pool:
    case SceneKind::drop:
      blocks = {Box{{0.0f, 0.0f, 0.0f}, {L, params.pool_height, D}}};
      break;
  }
  for (const Box& b : blocks) water_volume += volume(b);
  // The spacing that fills the water's volume with n particles; a handful of particles would
  // space wider than the tank is deep, so theirs is capped and they make a smaller puddle.
  const glm::vec3 tank_size = scene.tank.size();
  const float widest_spacing =
      kWidestSpacingOfThinnestSide * std::min({tank_size.x, tank_size.y, tank_size.z});
  auto spacing_for = [&](float filled_volume) {
    return std::min(std::cbrt(filled_volume / static_cast<float>(n)), widest_spacing);
  };

  if (params.kind != SceneKind::drop) {
    scene.spacing = spacing_for(water_volume);
    fill_blocks(blocks, scene.spacing, n, scene.particles);
    return scene;
  }

  // Drop: a pool plus a ball above it; the ball gets its share by volume, cut from the lattice.
  const float r = params.drop_radius;
  const float ball_volume = 4.0f / 3.0f * kPi * r * r * r;
  scene.spacing = spacing_for(water_volume + ball_volume);
  const glm::vec3 centre{0.5f * L, params.drop_height, 0.5f * D};
  std::vector<glm::vec3> ball = ball_of_particles(centre, r, scene.spacing, scene.tank);
  const int ball_count = std::min(static_cast<int>(ball.size()), n - 1);
  fill_blocks(blocks, scene.spacing, n - ball_count, scene.particles);
  for (int i = 0; i < ball_count; ++i) {
    scene.particles.append(ball[static_cast<std::size_t>(i)], glm::vec3(0.0f),
                           static_cast<std::uint32_t>(scene.particles.size()));
  }
  return scene;
}

std::vector<glm::vec3> ball_of_particles(glm::vec3 centre, float radius, float spacing,
                                         const Box& tank) {
  std::vector<glm::vec3> points;
  const int steps = static_cast<int>(std::floor(radius / spacing));
  for (int k = -steps; k <= steps; ++k) {
    for (int j = -steps; j <= steps; ++j) {
      for (int i = -steps; i <= steps; ++i) {
        const glm::vec3 offset = glm::vec3(i, j, k) * spacing;
        const glm::vec3 p = centre + offset;
        if (offset.x * offset.x + offset.y * offset.y + offset.z * offset.z <= radius * radius &&
            tank.contains(p)) {
          points.push_back(p);
        }
      }
    }
  }
  return points;
}

}  // namespace fluidcast::sim

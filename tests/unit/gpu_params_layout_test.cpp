// The C++ mirror of the solvers' parameter block (gpu_sim_params.h) against the layout the shader
// compiler gave the GLSL block: every member's name and offset, read from the embedded SPIR-V.
#include <gtest/gtest.h>

#include <cstddef>
#include <map>
#include <string>

#include "fluidcast_shaders/fluidcast_sim.h"
#include "gpu/gpu_sim_params.h"

namespace fluidcast::sim::gpu_solver {
namespace {

constexpr std::uint32_t kOpName = 5, kOpMemberName = 6, kOpMemberDecorate = 72;
constexpr std::uint32_t kDecorationOffset = 35;

std::string literal_string(std::span<const std::uint32_t> words) {
  std::string text;
  for (std::uint32_t word : words) {
    for (int byte = 0; byte < 4; ++byte) {
      const char c = static_cast<char>((word >> (8 * byte)) & 0xff);
      if (c == '\0') return text;
      text += c;
    }
  }
  return text;
}

// Member name → offset of the struct named `type_name` in a SPIR-V module.
std::map<std::string, std::uint32_t> member_offsets(std::span<const std::uint32_t> spirv,
                                                    const std::string& type_name) {
  std::uint32_t type_id = 0;
  std::map<std::uint32_t, std::string> names;
  std::map<std::uint32_t, std::uint32_t> offsets;
  for (int pass = 0; pass < 2; ++pass) {
    for (std::size_t at = 5; at < spirv.size();) {
      const std::uint32_t count = spirv[at] >> 16, opcode = spirv[at] & 0xffff;
      const auto operands = spirv.subspan(at + 1, count - 1);
      if (pass == 0 && opcode == kOpName && literal_string(operands.subspan(1)) == type_name) {
        type_id = operands[0];
      } else if (pass == 1 && opcode == kOpMemberName && operands[0] == type_id) {
        names[operands[1]] = literal_string(operands.subspan(2));
      } else if (pass == 1 && opcode == kOpMemberDecorate && operands[0] == type_id &&
                 operands[2] == kDecorationOffset) {
        offsets[operands[1]] = operands[3];
      }
      at += count;
    }
  }
  std::map<std::string, std::uint32_t> result;
  for (const auto& [member, name] : names) result[name] = offsets.at(member);
  return result;
}

#define FIELD(type, name) \
  { #name, offsetof(type, name) }

TEST(GpuParamsLayout, SimParamsMatchesTheGlslBlock) {
  const std::map<std::string, std::size_t> cpp = {FIELD(SimParams, position),
                                                  FIELD(SimParams, velocity),
                                                  FIELD(SimParams, id),
                                                  FIELD(SimParams, sorted_position),
                                                  FIELD(SimParams, sorted_velocity),
                                                  FIELD(SimParams, sorted_id),
                                                  FIELD(SimParams, predicted),
                                                  FIELD(SimParams, iterate),
                                                  FIELD(SimParams, iterate_scalar),
                                                  FIELD(SimParams, vorticity),
                                                  FIELD(SimParams, density),
                                                  FIELD(SimParams, acceleration),
                                                  FIELD(SimParams, order),
                                                  FIELD(SimParams, cell_start),
                                                  FIELD(SimParams, sorted_cell),
                                                  FIELD(SimParams, cell_of),
                                                  FIELD(SimParams, rank),
                                                  FIELD(SimParams, stats),
                                                  FIELD(SimParams, density_ratio),
                                                  FIELD(SimParams, neighbours),
                                                  FIELD(SimParams, neighbour_count),
                                                  FIELD(SimParams, wall_fluid_min),
                                                  FIELD(SimParams, wall_fluid_max),
                                                  FIELD(SimParams, inner_min),
                                                  FIELD(SimParams, inner_max),
                                                  FIELD(SimParams, gravity),
                                                  FIELD(SimParams, grid_dims),
                                                  FIELD(SimParams, grid_origin),
                                                  FIELD(SimParams, solver),
                                                  FIELD(SimParams, particle_count),
                                                  FIELD(SimParams, collider_count),
                                                  FIELD(SimParams, h),
                                                  FIELD(SimParams, h2),
                                                  FIELD(SimParams, poly6),
                                                  FIELD(SimParams, spiky),
                                                  FIELD(SimParams, viscosity_laplacian),
                                                  FIELD(SimParams, mass),
                                                  FIELD(SimParams, rest_density),
                                                  FIELD(SimParams, inv_rest_density),
                                                  FIELD(SimParams, rest_volume),
                                                  FIELD(SimParams, particle_radius),
                                                  FIELD(SimParams, relaxation_epsilon),
                                                  FIELD(SimParams, scorr_scale),
                                                  FIELD(SimParams, inv_w_dq),
                                                  FIELD(SimParams, scorr_exponent),
                                                  FIELD(SimParams, vorticity_epsilon),
                                                  FIELD(SimParams, xsph),
                                                  FIELD(SimParams, tait_stiffness),
                                                  FIELD(SimParams, tait_exponent),
                                                  FIELD(SimParams, sph_viscosity),
                                                  FIELD(SimParams, artificial_viscosity),
                                                  FIELD(SimParams, softening),
                                                  FIELD(SimParams, substep_travel),
                                                  FIELD(SimParams, max_candidates),
                                                  FIELD(SimParams, max_acceleration),
                                                  FIELD(SimParams, max_neighbours),
                                                  FIELD(SimParams, wall_reach),
                                                  FIELD(SimParams, stiffness_share),
                                                  FIELD(SimParams, pressed_from),
                                                  FIELD(SimParams, pressed_span),
                                                  FIELD(SimParams, max_speed),
                                                  FIELD(SimParams, collider_sphere),
                                                  FIELD(SimParams, collider_velocity)};
  const auto glsl = member_offsets(shaders::sim_pbf_lambda_comp, "SimParams");
  ASSERT_EQ(glsl.size(), cpp.size()) << "the GLSL block and the C++ struct differ in members";
  for (const auto& [name, offset] : cpp) {
    ASSERT_TRUE(glsl.count(name)) << name << " is not in the GLSL block";
    EXPECT_EQ(glsl.at(name), offset) << name;
  }
}

TEST(GpuParamsLayout, SimPassMatchesThePushConstants) {
  const std::map<std::string, std::size_t> cpp = {FIELD(SimPass, params),
                                                  FIELD(SimPass, dt),
                                                  FIELD(SimPass, time_into_step),
                                                  FIELD(SimPass, last_substep),
                                                  FIELD(SimPass, correction_weight),
                                                  FIELD(SimPass, write_velocity)};
  const auto glsl = member_offsets(shaders::sim_pbf_lambda_comp, "SimPass");
  ASSERT_EQ(glsl.size(), cpp.size());
  for (const auto& [name, offset] : cpp) EXPECT_EQ(glsl.at(name), offset) << name;
}

}  // namespace
}  // namespace fluidcast::sim::gpu_solver

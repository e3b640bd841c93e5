#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <type_traits>
#include <variant>

#include "fluidcast/sim/scene.h"
#include "fluidcast/sim/solver.h"

namespace fluidcast::sim {
namespace {

std::string error_of(const SolverParams& p) {
  try {
    validate(p);
  } catch (const ParamError& e) {
    return e.what();
  }
  return "";
}

// A ParamError names parameters, and each front end words them: flags on the command line, what
// a client sent (or the server's own setting) over the protocol.
TEST(ParamError, NamesItsParametersAsEachReaderKnowsThem) {
  SceneParams scene;
  scene.kind = SceneKind::dam_break;
  scene.column_width = scene.tank_length + 1.0f;
  try {
    validate(scene);
    FAIL() << "accepted";
  } catch (const ParamError& e) {
    EXPECT_STREQ(e.what(), "--column-width: must be less than --tank-length");
    EXPECT_EQ(e.worded([](std::string_view name) { return "the server's " + std::string(name); }),
              "the server's column-width: must be less than the server's tank-length");
  }
  EXPECT_STREQ(ParamError("no parameter named").what(), "no parameter named");
}

TEST(SolverParams, DefaultsAreValid) { EXPECT_NO_THROW(validate(SolverParams{})); }

TEST(SolverParams, EveryDefaultLiesInItsRangeAndEveryNameIsUnique) {
  std::set<std::string_view> names;
  for (const auto& spec : solver_param_specs()) {
    const double value = spec.get(SolverParams{});
    EXPECT_GE(value, spec.min) << spec.name;
    EXPECT_LE(value, spec.max) << spec.name;
    EXPECT_FALSE(spec.description.empty()) << spec.name;
    EXPECT_TRUE(names.insert(spec.name).second) << spec.name;
  }
  for (const auto& spec : scene_param_specs()) EXPECT_TRUE(names.insert(spec.name).second);
}

TEST(SolverParams, OutOfRangeNamesTheFlagAndRange) {
  SolverParams p;
  p.xsph_viscosity = 3.0f;
  EXPECT_EQ(error_of(p), "--xsph-viscosity: value 3 is out of range; accepted range [0, 1] 1");
  p = SolverParams{};
  p.iterations = 0;
  EXPECT_NE(error_of(p).find("--iterations"), std::string::npos);
}

// A float set to a bound holds the float nearest it (0.1f is a little over 0.1): still accepted.
TEST(SolverParams, EveryBoundItselfIsAccepted) {
  for (const auto& spec : solver_param_specs()) {
    for (const double bound : {spec.min, spec.max}) {
      SolverParams p;
      std::visit(
          [&](auto field) { p.*field = static_cast<std::remove_reference_t<decltype(p.*field)>>(bound); },
          spec.member);
      EXPECT_EQ(error_of(p), "") << spec.name << " = " << bound;
    }
  }
}

TEST(SolverParams, NonFiniteIsRefused) {
  SolverParams p;
  p.time_step = std::nanf("");
  EXPECT_NE(error_of(p).find("--time-step: value nan is not a finite number"), std::string::npos);
  p = SolverParams{};
  p.rest_density = INFINITY;
  EXPECT_NE(error_of(p).find("--rest-density"), std::string::npos);
}

TEST(Names, UnknownSceneAndSolverListTheChoices) {
  EXPECT_EQ(parse_scene("drop"), SceneKind::drop);
  EXPECT_EQ(parse_solver("sph"), SolverKind::sph);
  try {
    parse_scene("tsunami");
    FAIL();
  } catch (const ParamError& e) {
    EXPECT_NE(std::string(e.what()).find("dam_break, double_dam_break, drop, pool"),
              std::string::npos);
  }
  EXPECT_THROW(parse_solver("flip"), ParamError);
}

TEST(Docs, TuningMarkdownListsEveryFlag) {
  const std::string md = describe_markdown(SolverParams{}, solver_param_specs());
  for (const auto& spec : solver_param_specs()) {
    EXPECT_NE(md.find("`--" + std::string(spec.name) + "`"), std::string::npos);
  }
}

}  // namespace
}  // namespace fluidcast::sim

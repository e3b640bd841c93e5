// The server's limits for its device: what the operator gave wins; else a CPU device gets 30
// ticks a second and no simulation beyond --sim-share, a GPU the ServerLimits defaults.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "options.h"

namespace fluidcast::server {
namespace {

ServerOptions read(std::vector<std::string> flags) {
  flags.insert(flags.begin(), "fluidcast-server");
  std::vector<const char*> argv;
  for (const std::string& flag : flags) argv.push_back(flag.c_str());
  CLI::App app;
  return read_server_options(app, static_cast<int>(argv.size()), argv.data());
}

TEST(ServerOptions, ACpuDeviceGetsNoSimulationBeyondItsShareUnlessGivenIt) {
  const ServerOptions defaults = read({});
  EXPECT_DOUBLE_EQ(defaults.limits_for(true, 1000).busy_share, ServerLimits{}.busy_share);
  EXPECT_DOUBLE_EQ(defaults.limits_for(false, 1000).busy_share, ServerLimits{}.sim_share);
  EXPECT_EQ(defaults.limits_for(false, 1000).target_fps, 30u);
  const ServerOptions given = read({"--busy-share", "0.7", "--sim-share", "0.4"});
  EXPECT_DOUBLE_EQ(given.limits_for(false, 1000).busy_share, 0.7);
  EXPECT_DOUBLE_EQ(given.limits_for(true, 1000).busy_share, 0.7);
  EXPECT_DOUBLE_EQ(read({"--sim-share", "0.4"}).limits_for(false, 1000).busy_share, 0.4);
}

TEST(ServerOptions, SharesMustBeFiniteAndInRange) {
  for (const char* flag : {"--sim-share", "--busy-share"}) {
    for (const char* value : {"nan", "inf", "0.99", "0", "x"}) {
      EXPECT_THROW(read({flag, value}), CLI::ValidationError) << flag << " " << value;
    }
  }
}

}  // namespace
}  // namespace fluidcast::server

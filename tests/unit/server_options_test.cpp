// The server's limits for its device: what the operator gave wins; else a CPU device gets 30
// ticks a second and no simulation beyond --sim-share, a GPU the ServerLimits defaults.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "fluidcast/gpu/memory.h"
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

// Flags that bound each other: each at the other's value passes, past it is refused.
TEST(ServerOptions, FlagsThatBoundEachOtherAreChecked) {
  EXPECT_NO_THROW(read({"--max-particles", "5000", "--default-particles", "5000"}));
  EXPECT_THROW(read({"--max-particles", "5000", "--default-particles", "5001"}),
               CLI::ValidationError);
  EXPECT_NO_THROW(read({"--max-fps", "90", "--target-fps", "90"}));
  EXPECT_THROW(read({"--max-fps", "90", "--target-fps", "91"}), CLI::ValidationError);
  const std::string block = std::to_string(gpu::MemoryAllocator::kBlockSize >> 20);
  EXPECT_NO_THROW(read({"--gpu-memory", block}));
  EXPECT_NO_THROW(read({"--gpu-memory", "0"}));  // no limit
  EXPECT_THROW(read({"--gpu-memory", std::to_string(std::stoul(block) - 1)}), CLI::ValidationError);
  const std::filesystem::path pem = std::filesystem::temp_directory_path() /
                                    ("server_options_test." + std::to_string(getpid()) + ".pem");
  std::ofstream(pem) << "not read here\n";
  EXPECT_THROW(read({"--tls-cert", pem.string()}), CLI::ValidationError);
  EXPECT_THROW(read({"--tls-key", pem.string()}), CLI::ValidationError);
  EXPECT_NO_THROW(read({"--tls-cert", pem.string(), "--tls-key", pem.string()}));
  std::filesystem::remove(pem);
}

// What the operator leaves out: sessions from one address, half of all, rounded up; and the
// limits for a device keep the default size and rate within the server's maxima.
TEST(ServerOptions, DefaultsFollowTheLimitsGiven) {
  EXPECT_EQ(read({"--max-sessions", "5"}).limits.max_sessions_per_address, 3u);
  EXPECT_EQ(read({"--max-sessions", "8"}).limits.max_sessions_per_address, 4u);
  EXPECT_EQ(read({"--max-sessions", "8", "--max-sessions-per-address", "8"})
                .limits.max_sessions_per_address,
            8u);
  const ServerOptions small = read({"--max-particles", "3000", "--max-fps", "24"});
  EXPECT_EQ(small.limits_for(true, 20000).default_particles, 3000u);  // the device fits more
  EXPECT_EQ(small.limits_for(true, 20000).target_fps, 24u);
  EXPECT_EQ(read({}).limits_for(true, 20000).default_particles, 20000u);
}

TEST(ServerOptions, OriginsAndBackendsAreReadAsWritten) {
  const ServerOptions origins =
      read({"--allow-origin", "https://example.org,http://localhost:8080"});
  EXPECT_EQ(origins.allowed_origins,
            (std::vector<std::string>{"https://example.org", "http://localhost:8080"}));
  for (const char* bad : {"example.org", "ftp://example.org", "https://example.org/page"}) {
    EXPECT_THROW(read({"--allow-origin", bad}), CLI::ValidationError) << bad;
  }
  EXPECT_EQ(read({"--server-name", "fluid.example.org,mybox.lan"}).server_names,
            (std::vector<std::string>{"fluid.example.org", "mybox.lan"}));
  for (const char* bad :
       {"https://fluid.example.org", "fluid.example.org:8080", "a/b", "", ".", "..", "a..b"}) {
    EXPECT_THROW(read({"--server-name", bad}), CLI::ValidationError) << bad;
  }
  EXPECT_EQ(read({"--backend", "cpu"}).backend, SolverBackend::cpu);
  EXPECT_EQ(read({"--backend", "gpu"}).backend, SolverBackend::gpu);
  EXPECT_EQ(read({"--backend", "auto"}).backend, SolverBackend::automatic);
}

}  // namespace
}  // namespace fluidcast::server

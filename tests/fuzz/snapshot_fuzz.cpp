// Fuzz target: any bytes as a Snapshot handed to the server (NewSession.state, PutSnapshot):
// the protocol's checks, then the density check that refuses clumps before a solver sees them.
#include <google/protobuf/stubs/logging.h>

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <vector>

#include "fluidcast/sim/fluid_constants.h"
#include "fluidcast/sim/solver.h"
#include "fluidcast/sim/solver_params.h"
#include "session/refusal.h"
#include "session/validation.h"

using namespace fluidcast;

// Protobuf logs every invalid UTF-8 string it refuses: thousands of lines, none of them a finding.
static const bool kQuiet = (google::protobuf::SetLogHandler(nullptr), true);

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  v1::ClientMessage message;
  if (!message.ParseFromArray(data, static_cast<int>(size))) return 0;
  if (!message.hello().create().has_state()) return 0;
  const v1::Snapshot& state = message.hello().create().state();
  static const server::ServerLimits limits;
  try {
    server::validate_hello(message, limits, std::nullopt);
  } catch (const server::Refusal&) {
    return 0;
  }
  std::vector<glm::vec3> positions;
  for (int k = 0; k + 2 < state.positions_size(); k += 3) {
    positions.emplace_back(state.positions(k), state.positions(k + 1), state.positions(k + 2));
  }
  static const sim::FluidConstants fluid = sim::derive_fluid_constants(0.02f, sim::SolverParams{});
  try {
    sim::check_density(positions, fluid);
  } catch (const std::invalid_argument&) {
  }
  return 0;
}

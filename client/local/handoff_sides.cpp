#include "handoff_sides.h"

#include "local_stream.h"
#include "stream_client.h"

namespace fluidcast::client {

HandoffSides handoff_sides(const std::string& server, std::uint32_t max_local_particles) {
  return {server,
          [server](const v1::Hello& hello,
                   std::stop_token closing) -> std::shared_ptr<FluidStream> {
            try {
              return std::make_shared<StreamClient>(connect(server), hello,
                                                    StreamClient::kWelcomeWithin, closing);
            } catch (const StreamError& e) {
              if (e.code() == grpc::StatusCode::UNAVAILABLE) throw Unreachable(e.what());
              if (e.code() == grpc::StatusCode::NOT_FOUND && hello.has_resume()) {
                throw Forgotten(e.what());
              }
              throw;
            }
          },
          [max_local_particles](const v1::Hello& hello) -> std::shared_ptr<FluidStream> {
            return std::make_shared<LocalStream>(hello, max_local_particles);
          }};
}

}  // namespace fluidcast::client

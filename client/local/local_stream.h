// Local mode: a session simulated and rendered in this process, with the server's own session
// code (gestures, drag, tilt, commands) behind the same FluidStream as a remote one; the CPU
// solver (or the GPU one on a hardware device), Marching Cubes by default at these counts.
#pragma once

#include <memory>

#include "fluid_stream.h"
#include "fluidcast/gpu/context.h"
#include "session/session_hub.h"

namespace fluidcast::client {

class LocalStream final : public FluidStream {
 public:
  static constexpr std::uint32_t kDefaultMaxParticles = 8000;

  // Throws std::invalid_argument naming the cap when the Hello asks for more particles, and
  // server::Refusal for anything else the session refuses.
  LocalStream(v1::Hello hello, std::uint32_t max_particles);
  ~LocalStream() override;

  const v1::Welcome& welcome() const override { return welcome_; }
  std::uint64_t send(v1::ClientMessage message) override;
  std::optional<v1::Frame> next_frame(std::chrono::milliseconds timeout) override;
  bool ended() const override;
  std::string end_reason() const override;

  // The fluid as it is now, and back (the handoff).
  v1::Snapshot snapshot();
  void load(const v1::Snapshot& snapshot);

 private:
  class Sink;

  gpu::Context context_;
  server::Metrics metrics_;
  std::unique_ptr<server::SessionHub> hub_;
  std::shared_ptr<Sink> sink_;
  std::shared_ptr<server::ViewerLink> viewer_;
  v1::Welcome welcome_;
};

}  // namespace fluidcast::client

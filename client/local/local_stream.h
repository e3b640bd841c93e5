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
  // What draws the fluid when the Hello or a Quality command names no renderer: at these counts
  // Marching Cubes is the finest surface and cheap enough for a CPU.
  static constexpr const char* kDefaultRenderer = "mc";

  // Throws std::invalid_argument naming the cap when the Hello asks for more particles, and
  // server::Refusal for anything else the session refuses.
  LocalStream(v1::Hello hello, std::uint32_t max_particles);
  ~LocalStream() override;

  const v1::Welcome& welcome() const override { return welcome_; }
  std::uint64_t send(v1::ClientMessage message) override;
  std::optional<v1::Frame> next_frame(std::chrono::milliseconds timeout) override;
  bool ended() const override;
  std::string end_reason() const override;
  bool lost() const override { return false; }  // nothing here goes away
  std::string close() override;                 // the viewer leaves; the session ends with it

  v1::Snapshot snapshot() override;
  void load(const v1::Snapshot& snapshot) override;

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

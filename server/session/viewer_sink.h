// Where a viewer's messages go: implemented by each transport, one per stream. Called from the
// GPU worker and the encoder pool, never from the transport's own threads, so an implementation
// only queues and returns; it must never block.
#pragma once

#include <memory>

#include "fluidcast/v1/fluidcast.pb.h"
#include "refusal.h"

namespace fluidcast::server {

class ViewerSink {
 public:
  virtual ~ViewerSink() = default;
  // Welcome first, then Frames. A Frame not yet written is replaced by a newer one (counted as
  // dropped): memory per viewer stays bounded however slowly the client reads. Returns false
  // when a frame was replaced.
  virtual bool deliver(std::shared_ptr<const v1::ServerMessage> message) = 0;
  // The session ends this viewer's stream (the server stops, the session failed).
  virtual void end(const Refusal& why) = 0;
};

}  // namespace fluidcast::server

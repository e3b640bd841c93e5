// A transport's hold on the viewer its stream opened: the only way a transport reaches a session.
// It posts the viewer's messages to the session and takes the viewer out of it when the stream
// ends — on leave(), or, failing that, when the last holder lets go (as a drop: the viewer may
// resume). Safe from any thread.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>

#include "fluidcast/v1/fluidcast.pb.h"
#include "viewer.h"

namespace fluidcast::server {

class Session;
class SessionHub;

class ViewerLink {
 public:
  ViewerLink(SessionHub& hub, std::shared_ptr<Session> session, std::uint32_t viewer);
  ~ViewerLink();
  ViewerLink(const ViewerLink&) = delete;
  ViewerLink& operator=(const ViewerLink&) = delete;

  // A validated message of the stream, applied at the session's next tick.
  void post(v1::ClientMessage message) const;
  // The stream ended: the viewer leaves its session, on the worker. Only the first call counts.
  void leave(Departure departure);

 private:
  SessionHub* hub_;
  std::shared_ptr<Session> session_;
  std::uint32_t viewer_;
  std::atomic<bool> left_{false};
};

}  // namespace fluidcast::server

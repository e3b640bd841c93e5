#include "viewer_link.h"

#include "session_hub.h"

namespace fluidcast::server {

ViewerLink::ViewerLink(SessionHub& hub, std::shared_ptr<Session> session, std::uint32_t viewer)
    : hub_(&hub), session_(std::move(session)), viewer_(viewer) {}

ViewerLink::~ViewerLink() {
  leave(Departure::dropped);
  // The link may hold a session's last reference, and a session dies on the worker: its solver
  // goes into the step batch that only the worker touches.
  hub_->post([session = std::move(session_)] {});
}

void ViewerLink::post(v1::ClientMessage message) const {
  session_->post(viewer_, std::move(message));
}

void ViewerLink::leave(Departure departure) {
  if (left_.exchange(true)) return;
  hub_->close(session_, viewer_, departure);
}

}  // namespace fluidcast::server

#include "viewer_link.h"

#include "session_hub.h"

namespace fluidcast::server {

ViewerLink::ViewerLink(SessionHub& hub, std::shared_ptr<Session> session, std::uint32_t viewer)
    : hub_(&hub), session_(std::move(session)), viewer_(viewer) {}

ViewerLink::~ViewerLink() { leave(Departure::dropped); }

void ViewerLink::post(v1::ClientMessage message) const {
  session_->post(viewer_, std::move(message));
}

void ViewerLink::leave(Departure departure) {
  if (left_.exchange(true)) return;
  hub_->close(session_, viewer_, departure);
}

}  // namespace fluidcast::server

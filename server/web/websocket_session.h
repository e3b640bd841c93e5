// One browser's stream on /ws: the same ClientMessage and ServerMessage as gRPC's Stream, one per
// binary WebSocket frame, with the same validation and session rules. All its work runs on its
// connection's strand; the session side reaches it only through its sink. At most one write in
// flight and one frame waiting behind it: a newer frame replaces the waiting one.
#pragma once

#include <boost/beast/http/message.hpp>
#include <boost/beast/http/string_body.hpp>
#include <memory>

#include "session/session_hub.h"
#include "web/http_server.h"

namespace fluidcast::server {

// Takes over an upgrade request's connection, and its slot; keeps itself alive while the socket
// is open. A socket that sends no Hello within ServerLimits::hello_timeout is ended.
void serve_websocket(WebStream stream,
                     boost::beast::http::request<boost::beast::http::string_body> request,
                     std::shared_ptr<ConnectionLimits::Slot> slot, SessionHub& hub);

}  // namespace fluidcast::server

// The server's HTTP side (Boost.Beast): the phone page and its files, the WebSocket on /ws,
// GET /metrics (Prometheus text) and GET /healthz, over plain HTTP and, with a TLS context, HTTPS
// on the same port (each connection's first bytes say which). One io_context on its own threads;
// each connection runs on its own strand and handles one request at a time. Connections are
// counted against ConnectionLimits; when the process runs out of descriptors the acceptor waits
// and tries again (the server then says it is unhealthy) instead of spinning.
#pragma once

#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/ssl/context.hpp>
#include <boost/beast/core/tcp_stream.hpp>
#include <boost/beast/http/message.hpp>
#include <boost/beast/http/string_body.hpp>
#include <boost/beast/ssl/ssl_stream.hpp>
#include <chrono>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <thread>
#include <variant>
#include <vector>

#include "net/connection_limits.h"
#include "net/listener.h"
#include "websocket_origins.h"

namespace fluidcast::server {

using TlsStream = boost::beast::ssl_stream<boost::beast::tcp_stream>;
// A connection as the HTTP side hands it over: plain, or TLS.
using WebStream = std::variant<boost::beast::tcp_stream, TlsStream>;

class HttpServer {
 public:
  struct Routes {
    std::function<std::string()> metrics;  // the body of /metrics
    // /healthz: 200 when true and the port can accept connections (descriptors left), else 503.
    std::function<bool()> healthy;
    // Takes over a WebSocket upgrade of /ws, with the connection's slot to hold while it is open.
    std::function<void(WebStream, boost::beast::http::request<boost::beast::http::string_body>,
                       std::shared_ptr<ConnectionLimits::Slot>)>
        websocket;
    // GET paths served from files ("/" is index.html).
    std::map<std::string, std::filesystem::path> files;
    // Which browsers' pages may open /ws; any other is refused with 403 (and logged): a page on
    // another site that a person on the LAN opens must not drive this server through their
    // browser.
    WebSocketOrigins websocket_origins;
  };
  // Listens on address:port (port 0: any free one); throws std::runtime_error naming the address
  // when it cannot. With `tls`, connections that open with a TLS handshake get HTTPS.
  HttpServer(const std::string& address, unsigned short port, Routes routes,
             ConnectionLimits limits, std::shared_ptr<boost::asio::ssl::context> tls = nullptr,
             unsigned threads = 2);
  ~HttpServer();
  HttpServer(const HttpServer&) = delete;
  HttpServer& operator=(const HttpServer&) = delete;

  unsigned short port() const { return listener_.port(); }
  // Stops serving once no connection but those waiting for their client is open, or `grace` is
  // over: time for the WebSockets that are ending to say why (a StreamEnd) and close.
  void stop(std::chrono::milliseconds grace = {});

 private:
  Routes routes_;
  ConnectionLimits limits_;
  std::shared_ptr<boost::asio::ssl::context> tls_;
  boost::asio::io_context io_;
  Listener listener_;
  std::vector<std::thread> threads_;
};

}  // namespace fluidcast::server

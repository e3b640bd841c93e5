#include "http_server.h"

#include <algorithm>
#include <boost/asio/strand.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/ssl.hpp>
#include <boost/beast/websocket/rfc6455.hpp>
#include <cctype>
#include <chrono>
#include <fstream>
#include <memory>
#include <optional>
#include <spdlog/spdlog.h>
#include <sstream>
#include <stdexcept>
#include <thread>

namespace fluidcast::server {
namespace {

namespace beast = boost::beast;
namespace http = beast::http;
using tcp = boost::asio::ip::tcp;

// Each exchange on a connection — the TLS detection and handshake, a request's read, a response's
// write — has this long; a client slower than that loses its connection, and its slot.
constexpr auto kExchangeTimeout = std::chrono::seconds(30);

std::string content_type(const std::filesystem::path& path) {
  const std::string extension = path.extension().string();
  if (extension == ".html") return "text/html; charset=utf-8";
  if (extension == ".js") return "text/javascript; charset=utf-8";
  if (extension == ".css") return "text/css; charset=utf-8";
  if (extension == ".png") return "image/png";
  if (extension == ".webmanifest") return "application/manifest+json";
  return "text/plain; charset=utf-8";
}

// One connection's requests over Stream (beast::tcp_stream or TlsStream); `buffer` holds what
// was read while telling TLS from plain HTTP.
template <class Stream>
class Connection : public std::enable_shared_from_this<Connection<Stream>> {
  using std::enable_shared_from_this<Connection<Stream>>::shared_from_this;

 public:
  Connection(Stream stream, beast::flat_buffer buffer, const HttpServer::Routes& routes,
             std::shared_ptr<ConnectionLimits::Slot> slot)
      : stream_(std::move(stream)),
        routes_(&routes),
        slot_(std::move(slot)),
        buffer_(std::move(buffer)) {}

  void read() {
    request_ = {};
    beast::get_lowest_layer(stream_).expires_after(kExchangeTimeout);
    slot_->set_awaiting(true);
    http::async_read(
        stream_, buffer_, request_,
        [self = shared_from_this()](beast::error_code error, std::size_t) {
          self->slot_->set_awaiting(false);
          if (error) return;
          const bool websocket = beast::websocket::is_upgrade(self->request_) &&
                                 self->request_.target() == "/ws" && self->routes_->websocket;
          if (websocket) {
            const auto origin = self->request_.find(http::field::origin);
            const beast::string_view host = self->request_[http::field::host];
            const std::optional<std::string> refused = self->routes_->websocket_origins.refusal(
                origin == self->request_.end()
                    ? std::nullopt
                    : std::optional<std::string_view>(
                          std::string_view(origin->value().data(), origin->value().size())),
                std::string_view(host.data(), host.size()));
            if (refused) {
              spdlog::warn("refused a WebSocket: {}", *refused);
              self->refuse_origin(*refused);
              return;
            }
          }
          if (websocket) {
            beast::get_lowest_layer(self->stream_).expires_never();
            self->routes_->websocket(WebStream(std::move(self->stream_)), std::move(self->request_),
                                     std::move(self->slot_));
            return;
          }
          self->respond();
        });
  }

 private:
  void refuse_origin(const std::string& why) {
    auto response = std::make_shared<http::response<http::string_body>>(http::status::forbidden,
                                                                        request_.version());
    response->set(http::field::server, "fluidcast");
    response->set(http::field::content_type, "text/plain; charset=utf-8");
    response->body() = why + "\n";
    response->keep_alive(false);
    response->prepare_payload();
    send(std::move(response));
  }

  void respond() {
    auto response = std::make_shared<http::response<http::string_body>>();
    response->version(request_.version());
    response->keep_alive(request_.keep_alive());
    response->set(http::field::server, "fluidcast");
    std::string target(request_.target());
    target = target.substr(0, target.find('?'));  // the page's own parameters are not a path
    if (request_.method() != http::verb::get && request_.method() != http::verb::head) {
      response->result(http::status::method_not_allowed);
      response->body() = "only GET\n";
    } else if (target == "/metrics") {
      response->set(http::field::content_type, "text/plain; version=0.0.4");
      response->body() = routes_->metrics();
    } else if (target == "/healthz") {
      const bool healthy = routes_->healthy();
      response->result(healthy ? http::status::ok : http::status::service_unavailable);
      response->body() = healthy ? "ok\n" : "stopping\n";
    } else if (const auto file = routes_->files.find(target); file != routes_->files.end()) {
      std::ifstream in(file->second, std::ios::binary);
      std::ostringstream body;
      body << in.rdbuf();
      if (in) {
        response->set(http::field::content_type, content_type(file->second));
        response->set(http::field::cache_control, "no-cache");
        // Cross-origin isolation: the page may then share memory with Web Workers, and its local
        // fluid steps on several threads (it loads nothing from other origins).
        response->set("Cross-Origin-Opener-Policy", "same-origin");
        response->set("Cross-Origin-Embedder-Policy", "require-corp");
        response->body() = body.str();
      } else {
        response->result(http::status::not_found);
        response->body() = file->second.string() + " is missing on the server\n";
      }
    } else {
      response->result(http::status::not_found);
      response->body() = "not found: try /, /metrics or /healthz\n";
    }
    if (request_.method() == http::verb::head) response->body().clear();
    response->prepare_payload();
    send(std::move(response));
  }

  void send(std::shared_ptr<http::response<http::string_body>> response) {
    // Its own time, not what the request's read left of it.
    beast::get_lowest_layer(stream_).expires_after(kExchangeTimeout);
    http::async_write(stream_, *response,
                      [self = shared_from_this(), response](beast::error_code error, std::size_t) {
                        if (error) return;
                        if (response->keep_alive()) {
                          self->read();
                        } else {
                          beast::error_code ignored;
                          beast::get_lowest_layer(self->stream_)
                              .socket()
                              .shutdown(tcp::socket::shutdown_send, ignored);
                        }
                      });
  }

  Stream stream_;
  const HttpServer::Routes* routes_;
  std::shared_ptr<ConnectionLimits::Slot> slot_;
  beast::flat_buffer buffer_;
  http::request<http::string_body> request_;
};

// Reads a new connection's first bytes: a TLS handshake gets HTTPS (when there is a context),
// anything else plain HTTP.
class Detector : public std::enable_shared_from_this<Detector> {
 public:
  Detector(tcp::socket socket, const HttpServer::Routes& routes,
           std::shared_ptr<boost::asio::ssl::context> tls,
           std::shared_ptr<ConnectionLimits::Slot> slot)
      : stream_(std::move(socket)),
        routes_(&routes),
        tls_(std::move(tls)),
        slot_(std::move(slot)) {}

  void run() {
    stream_.expires_after(kExchangeTimeout);
    beast::async_detect_ssl(
        stream_, buffer_, [self = shared_from_this()](beast::error_code error, bool tls) {
          if (error) return;
          if (tls && self->tls_) {
            self->handshake();
          } else {
            std::make_shared<Connection<beast::tcp_stream>>(std::move(self->stream_),
                                                            std::move(self->buffer_),
                                                            *self->routes_, std::move(self->slot_))
                ->read();
          }
        });
  }

 private:
  void handshake() {
    auto secure = std::make_shared<TlsStream>(std::move(stream_), *tls_);
    secure->async_handshake(
        boost::asio::ssl::stream_base::server, buffer_.data(),
        [self = shared_from_this(), secure](beast::error_code error, std::size_t used) {
          if (error) return;  // a browser that does not trust the certificate yet, say
          self->buffer_.consume(used);
          std::make_shared<Connection<TlsStream>>(std::move(*secure), std::move(self->buffer_),
                                                  *self->routes_, std::move(self->slot_))
              ->read();
        });
  }

  beast::tcp_stream stream_;
  const HttpServer::Routes* routes_;
  std::shared_ptr<boost::asio::ssl::context> tls_;
  std::shared_ptr<ConnectionLimits::Slot> slot_;
  beast::flat_buffer buffer_;
};

}  // namespace

HttpServer::HttpServer(const std::string& address, unsigned short port, Routes routes,
                       ConnectionLimits limits, std::shared_ptr<boost::asio::ssl::context> tls,
                       unsigned threads)
    : routes_(std::move(routes)),
      limits_(std::move(limits)),
      tls_(std::move(tls)),
      listener_(io_, address, port, "HTTP") {
  routes_.healthy = [serving = std::move(routes_.healthy), this] {
    return serving() && listener_.accepting();
  };
  listener_.start([this](tcp::socket socket, boost::asio::ip::address client) {
    if (auto slot = limits_.admit(client)) {
      std::make_shared<Detector>(std::move(socket), routes_, tls_, std::move(slot))->run();
    }  // else the socket closes here: over a limit
  });
  for (unsigned k = 0; k < threads; ++k) threads_.emplace_back([this] { io_.run(); });
}

HttpServer::~HttpServer() { stop(); }

void HttpServer::stop(std::chrono::milliseconds grace) {
  // WebSockets whose sessions were ended write their StreamEnd and close, and requests under way
  // are answered; connections waiting for their client (a page's keep-alive) are cut at once.
  const auto until = std::chrono::steady_clock::now() + grace;
  while (limits_.busy() > 0 && std::chrono::steady_clock::now() < until) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  io_.stop();
  for (auto& thread : threads_) {
    if (thread.joinable()) thread.join();
  }
}

}  // namespace fluidcast::server

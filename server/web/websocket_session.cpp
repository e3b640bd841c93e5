#include "websocket_session.h"

#include <google/protobuf/io/zero_copy_stream_impl_lite.h>
#include <spdlog/spdlog.h>

#include <boost/asio/post.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/beast/core/flat_buffer.hpp>
#include <boost/beast/ssl.hpp>
#include <boost/beast/websocket.hpp>
#include <boost/beast/websocket/ssl.hpp>
#include <variant>

#include "session/input_rules.h"
#include "session/outgoing_messages.h"
#include "session/stream_protocol.h"

namespace fluidcast::server {
namespace {

namespace beast = boost::beast;
namespace websocket = beast::websocket;

constexpr std::size_t kReadPiece = 64 * 1024;

// Over a plain connection or a TLS one (Stream: beast::tcp_stream or TlsStream).
template <class Stream>
class WebSocketSession : public std::enable_shared_from_this<WebSocketSession<Stream>> {
  using std::enable_shared_from_this<WebSocketSession<Stream>>::shared_from_this;
  using std::enable_shared_from_this<WebSocketSession<Stream>>::weak_from_this;

 public:
  WebSocketSession(Stream stream, std::shared_ptr<ConnectionLimits::Slot> slot, SessionHub& hub)
      : socket_(std::move(stream)),
        slot_(std::move(slot)),
        hub_(&hub),
        protocol_(hub.limits(), hub.token()),
        hello_deadline_(socket_.get_executor()) {}

  void start(beast::http::request<beast::http::string_body> request) {
    hello_deadline_.expires_after(hub_->limits().hello_timeout);
    hello_deadline_.async_wait([self = shared_from_this()](beast::error_code error) {
      if (error || self->viewer_ || self->opening_) return;  // cancelled, or the Hello came
      self->refuse(self->protocol_.no_hello());
    });
    // Pings after 5 s of silence; a phone that does not answer within 15 s is gone, and its
    // viewer leaves (a resume finds its camera).
    socket_.set_option(
        websocket::stream_base::timeout{std::chrono::seconds(10), std::chrono::seconds(15), true});
    // A backstop: read() ends a larger message itself, with a StreamEnd, one piece past the limit.
    socket_.read_message_max(kMaxClientMessageBytes + 2 * kReadPiece);
    socket_.binary(true);
    socket_.async_accept(request, [self = shared_from_this()](beast::error_code error) {
      if (!error) {
        self->read();
      } else {  // no WebSocket came of it: its descriptor and slot go now, not at the Hello timeout
        self->hello_deadline_.cancel();
      }
    });
  }

  // From any thread: onto the strand.
  void post_send(std::shared_ptr<const v1::ServerMessage> message) {
    boost::asio::post(
        socket_.get_executor(),
        [self = shared_from_this(), message = std::move(message)] { self->send(message); });
  }
  void post_end(const Refusal& why) {
    boost::asio::post(socket_.get_executor(), [self = shared_from_this(), why] { self->end(why); });
  }

 private:
  // The session's way in: a weak link, so a closed socket is simply gone.
  class Sink final : public ViewerSink {
   public:
    explicit Sink(std::weak_ptr<WebSocketSession> owner) : owner_(std::move(owner)) {}
    bool deliver(std::shared_ptr<const v1::ServerMessage> message) override {
      if (auto owner = owner_.lock()) owner->post_send(std::move(message));
      return true;  // replacements are counted on the strand
    }
    void end(const Refusal& why) override {
      if (auto owner = owner_.lock()) owner->post_end(why);
    }

   private:
    std::weak_ptr<WebSocketSession> owner_;
  };

  // A message a piece at a time: one that grows past kMaxClientMessageBytes is refused with a
  // StreamEnd before more of it is buffered (Beast's own limit would close the socket without one).
  void read() {
    if (ending_) return;
    socket_.async_read_some(buffer_, kReadPiece,
                            [self = shared_from_this()](beast::error_code error, std::size_t) {
                              self->on_read(error);
                            });
  }

  void on_read(beast::error_code error) {
    if (error) {  // closed or broken
      // A close frame with "normal closure" is a goodbye; anything else (going away, no code, a
      // broken connection) may come back.
      const bool goodbye = error == websocket::error::closed &&
                           socket_.reason().code == websocket::close_code::normal;
      leave(goodbye ? Departure::left : Departure::dropped);
      return;
    }
    // A read that completed as the stream was being ended (a Hello just after its deadline)
    // opens and posts nothing: the socket is closing.
    if (ending_) return;
    if (buffer_.size() > kMaxClientMessageBytes) {
      buffer_.consume(buffer_.size());
      refuse(Refusal(RefusalCode::resource_exhausted,
                     "a WebSocket message over " + std::to_string(kMaxClientMessageBytes / 1024) +
                         " KiB (the largest a ClientMessage can be)"));
      return;
    }
    if (!socket_.is_message_done()) {
      read();
      return;
    }
    try {
      auto next = [this] {
        google::protobuf::io::ArrayInputStream bytes(buffer_.data().data(),
                                                     static_cast<int>(buffer_.size()));
        return protocol_.receive(bytes);
      }();
      buffer_.consume(buffer_.size());
      if (auto* hello = std::get_if<StreamProtocol::Open>(&next)) {
        hello_deadline_.cancel();
        opening_ = true;
        open(hello->hello);
        return;  // the next read starts once the session is open
      }
      viewer_->post(std::move(std::get<StreamProtocol::Post>(next).message));
      read();
    } catch (const Refusal& refusal) {
      refuse(refusal);
    }
  }

  // Ends the stream with a StreamEnd saying why; the viewer leaves now, and the socket closes once
  // the StreamEnd is written.
  void refuse(const Refusal& refusal) {
    end(refusal);
    leave();
  }

  void open(const v1::Hello& hello) {
    auto sink = std::make_shared<Sink>(weak_from_this());
    hub_->open(hello, slot_->address().to_string(), sink,
               [self = shared_from_this()](SessionHub::Opened opened) {
                 boost::asio::post(self->socket_.get_executor(),
                                   [self, opened = std::move(opened)]() mutable {
                                     if (opened.refusal) {
                                       self->end(*opened.refusal);
                                       return;
                                     }
                                     // The socket went away while the session opened: the link,
                                     // dropped, takes the viewer out.
                                     if (self->ending_) return;
                                     self->viewer_ = std::move(opened.viewer);
                                     self->protocol_.opened(opened.access);
                                     self->read();
                                   });
               });
  }

  void send(std::shared_ptr<const v1::ServerMessage> message) {
    if (ending_ && !message->has_end()) return;
    if (!outgoing_.push(std::move(message))) hub_->metrics().frames_dropped++;
    if (!writing_) write_next();
  }

  void write_next() {
    const std::shared_ptr<const v1::ServerMessage> next = outgoing_.next();
    if (!next) {
      if (ending_ && !closed_) close();
      return;
    }
    writing_ = std::make_shared<std::string>(next->SerializeAsString());
    socket_.async_write(boost::asio::buffer(*writing_),
                        [self = shared_from_this()](beast::error_code error, std::size_t) {
                          self->writing_.reset();
                          const auto send_ms = self->outgoing_.written();
                          if (error) {
                            self->leave();
                            return;
                          }
                          if (send_ms) self->hub_->metrics().sent(Transport::websocket, *send_ms);
                          self->write_next();
                        });
  }

  // Says why in a StreamEnd, then closes once it is written; counted and logged once.
  void end(const Refusal& why) {
    if (ending_) return;
    ending_ = true;
    record_refusal(hub_->metrics(), Transport::websocket, why);
    outgoing_.stop_frames();
    auto message = std::make_shared<v1::ServerMessage>();
    message->mutable_end()->set_code(refusal_code_name(why.code()));
    message->mutable_end()->set_message(why.what());
    outgoing_.push(std::move(message));
    if (!writing_) write_next();
  }

  void close() {
    closed_ = true;
    socket_.async_close(websocket::close_code::normal,
                        [self = shared_from_this()](beast::error_code) { self->leave(); });
  }

  // The viewer leaves its session (once).
  void leave(Departure departure = Departure::dropped) {
    hello_deadline_.cancel();
    ending_ = true;
    outgoing_.stop_frames();
    if (viewer_) viewer_->leave(departure);
    viewer_.reset();
  }

  websocket::stream<Stream> socket_;
  std::shared_ptr<ConnectionLimits::Slot> slot_;
  SessionHub* hub_;
  beast::flat_buffer buffer_;
  StreamProtocol protocol_;
  std::shared_ptr<ViewerLink> viewer_;
  std::shared_ptr<std::string> writing_;
  OutgoingMessages outgoing_;
  boost::asio::steady_timer hello_deadline_;
  bool opening_ = false;  // a Hello came; its session is being opened
  bool ending_ = false, closed_ = false;
};

}  // namespace

void serve_websocket(WebStream stream, beast::http::request<beast::http::string_body> request,
                     std::shared_ptr<ConnectionLimits::Slot> slot, SessionHub& hub) {
  std::visit(
      [&](auto& connection) {
        using Stream = std::decay_t<decltype(connection)>;
        std::make_shared<WebSocketSession<Stream>>(std::move(connection), std::move(slot), hub)
            ->start(std::move(request));
      },
      stream);
}

}  // namespace fluidcast::server

// What an idle or greedy client can hold of the real server on loopback: streams that send no
// Hello end at their deadline on both transports (a failed WebSocket handshake at once), HTTP,
// WebSocket and gRPC connections over the limits are closed while the others are served, and when
// the process runs out of descriptors neither port spins nor stays deaf once they come back, in
// plaintext or TLS.
#include <arpa/inet.h>
#include <grpcpp/create_channel.h>
#include <grpcpp/security/credentials.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <boost/asio/connect.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core/flat_buffer.hpp>
#include <boost/beast/websocket.hpp>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <optional>
#include <thread>
#include <vector>

#include "fluidcast/v1/fluidcast.grpc.pb.h"
#include "server_process.h"
#include "stream_client.h"
#include "web/tls_certificate.h"

namespace fluidcast {
namespace {

using Clock = std::chrono::steady_clock;
using std::chrono::milliseconds;
using std::chrono::seconds;
using testing::RawConnection;

// A Hello that opens a small session.
v1::Hello small_session() {
  v1::Hello hello;
  hello.mutable_viewport()->set_width(64);
  hello.mutable_viewport()->set_height(48);
  hello.mutable_create()->set_particles(500);
  return hello;
}

// 120 idle connections to the server's gRPC port, which has no total of its own (the server must
// be started with a per-address limit above 120): with 96 descriptors, they take every one left.
std::vector<std::unique_ptr<RawConnection>> flood_grpc_port(const testing::ServerProcess& server) {
  std::vector<std::unique_ptr<RawConnection>> flood;
  const std::string& address = server.grpc_address();
  const int grpc_port = std::stoi(address.substr(address.rfind(':') + 1));
  for (int k = 0; k < 120; ++k) flood.push_back(std::make_unique<RawConnection>(grpc_port));
  return flood;
}

// The server's health asked on `monitor` until it is no longer 200 (or 10 s have passed): the
// server accepts a flood's connections one by one, slower under a sanitizer or beside a build.
std::string health_once_flooded(RawConnection& monitor) {
  std::string answer;
  for (const auto give_up = Clock::now() + seconds(10); Clock::now() < give_up;) {
    answer = monitor.get("/healthz");
    if (answer != "HTTP/1.1 200 OK") break;
    std::this_thread::sleep_for(milliseconds(100));
  }
  return answer;
}

// A WebSocket to the server's /ws; reads give up after 20 s, so that a server that never answers
// fails the test instead of hanging it.
using WebSocket = boost::beast::websocket::stream<boost::asio::ip::tcp::socket>;
std::unique_ptr<WebSocket> open_websocket(boost::asio::io_context& io, int port) {
  auto socket = std::make_unique<WebSocket>(io);
  socket->next_layer().connect(
      {boost::asio::ip::make_address("127.0.0.1"), static_cast<unsigned short>(port)});
  const timeval wait{20, 0};
  setsockopt(socket->next_layer().native_handle(), SOL_SOCKET, SO_RCVTIMEO, &wait, sizeof wait);
  socket->handshake("127.0.0.1", "/ws");
  return socket;
}

TEST(ConnectionLimitsTest, AgRpcStreamThatSendsNoHelloEndsAtItsDeadline) {
  testing::ServerProcess server({"--hello-timeout", "1"});
  auto stub = v1::Fluidcast::NewStub(client::connect(server.grpc_address()));
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + seconds(30));
  const auto opened = Clock::now();
  auto stream = stub->Stream(&context);
  v1::ServerMessage message;
  while (stream->Read(&message)) {
  }
  const grpc::Status status = stream->Finish();
  const double waited = std::chrono::duration<double>(Clock::now() - opened).count();
  EXPECT_EQ(status.error_code(), grpc::StatusCode::DEADLINE_EXCEEDED) << status.error_message();
  EXPECT_NE(status.error_message().find("no Hello within 1 s"), std::string::npos)
      << status.error_message();
  EXPECT_GE(waited, 0.9);
  EXPECT_LT(waited, 10.0);
}

TEST(ConnectionLimitsTest, AWebSocketThatSendsNoHelloEndsAtItsDeadline) {
  testing::ServerProcess server({"--hello-timeout", "1"});
  namespace websocket = boost::beast::websocket;
  boost::asio::io_context io;
  const auto connection = open_websocket(io, server.http_port());
  WebSocket& socket = *connection;
  const auto opened = Clock::now();
  boost::beast::flat_buffer buffer;
  boost::beast::error_code error;
  socket.read(buffer, error);
  ASSERT_FALSE(error) << error.message();
  v1::ServerMessage message;
  ASSERT_TRUE(message.ParseFromArray(buffer.data().data(), static_cast<int>(buffer.size())));
  ASSERT_TRUE(message.has_end());
  EXPECT_EQ(message.end().code(), "DEADLINE_EXCEEDED");
  EXPECT_NE(message.end().message().find("no Hello within 1 s"), std::string::npos)
      << message.end().message();
  EXPECT_GE(std::chrono::duration<double>(Clock::now() - opened).count(), 0.9);
  buffer.clear();
  socket.read(buffer, error);  // then the server closes it
  EXPECT_EQ(error, websocket::error::closed) << error.message();
}

// A server that stops tells its WebSocket viewers why, as gRPC's get a status: a StreamEnd
// (UNAVAILABLE), then the close.
TEST(ConnectionLimitsTest, AStoppingServerTellsItsWebSocketViewersWhy) {
  testing::ServerProcess server;
  namespace websocket = boost::beast::websocket;
  boost::asio::io_context io;
  const auto connection = open_websocket(io, server.http_port());
  WebSocket& socket = *connection;
  socket.binary(true);
  v1::ClientMessage hello;
  *hello.mutable_hello() = small_session();
  socket.write(boost::asio::buffer(hello.SerializeAsString()));
  boost::beast::flat_buffer buffer;
  boost::beast::error_code error;
  v1::ServerMessage message;
  socket.read(buffer, error);
  ASSERT_FALSE(error) << error.message();
  ASSERT_TRUE(message.ParseFromArray(buffer.data().data(), static_cast<int>(buffer.size())));
  ASSERT_TRUE(message.has_welcome());
  std::thread stopping([&server] { server.stop(); });
  std::optional<v1::StreamEnd> end;
  while (!error && !end) {
    buffer.clear();
    socket.read(buffer, error);
    if (!error && message.ParseFromArray(buffer.data().data(), static_cast<int>(buffer.size())) &&
        message.has_end()) {
      end = message.end();
    }
  }
  if (end) {  // then the server closes it, waiting for the close handshake
    buffer.clear();
    socket.read(buffer, error);
  }
  stopping.join();
  ASSERT_TRUE(end) << "the socket ended without a StreamEnd: " << error.message();
  EXPECT_EQ(end->code(), "UNAVAILABLE") << end->message();
  EXPECT_EQ(error, websocket::error::closed) << error.message();
}

// The second a stopping server gives its WebSockets to say goodbye is not spent on a page's idle
// keep-alive connection: a server with one stops about as fast as one without.
TEST(ConnectionLimitsTest, AnIdlePageConnectionDoesNotHoldUpTheShutdown) {
  const auto stop_seconds = [](testing::ServerProcess& server) {
    const auto asked = Clock::now();
    EXPECT_EQ(server.stop(), 0);
    return std::chrono::duration<double>(Clock::now() - asked).count();
  };
  testing::ServerProcess alone;
  const double alone_stops = stop_seconds(alone);
  // The quicker of two: a loaded machine only slows a stop, and waiting for the page would take
  // the whole second of goodbye each time.
  double with_page_stops = 1e9;
  for (int run = 0; run < 2; ++run) {
    testing::ServerProcess server;
    RawConnection page(server.http_port());
    ASSERT_EQ(page.get("/healthz"), "HTTP/1.1 200 OK");
    with_page_stops = std::min(with_page_stops, stop_seconds(server));
  }
  EXPECT_LT(with_page_stops, alone_stops + 0.6)
      << "alone " << alone_stops << " s, with an idle page " << with_page_stops << " s";
}

// A WebSocket message larger than any ClientMessage ends its stream with a StreamEnd saying so,
// before the server buffers the rest of it; another stream goes on.
TEST(ConnectionLimitsTest, AnOversizedWebSocketMessageEndsWithAStreamEnd) {
  testing::ServerProcess server;
  client::StreamClient bystander(client::connect(server.grpc_address()), small_session());
  boost::asio::io_context io;
  const auto connection = open_websocket(io, server.http_port());
  WebSocket& socket = *connection;
  socket.binary(true);
  socket.write_buffer_bytes(64 * 1024);
  const std::string huge(8u << 20, 'x');  // 8 MiB: over the 448 KiB a ClientMessage may be
  boost::beast::error_code error;
  socket.write(boost::asio::buffer(huge), error);  // the server may stop reading midway
  boost::beast::flat_buffer buffer;
  socket.read(buffer, error);
  ASSERT_FALSE(error) << error.message();
  v1::ServerMessage message;
  ASSERT_TRUE(message.ParseFromArray(buffer.data().data(), static_cast<int>(buffer.size())));
  ASSERT_TRUE(message.has_end());
  EXPECT_EQ(message.end().code(), "RESOURCE_EXHAUSTED");
  EXPECT_NE(message.end().message().find("KiB"), std::string::npos) << message.end().message();
  EXPECT_FALSE(bystander.next_frame(seconds(30)) == std::nullopt);
}

// A page on another site, opened by someone on the LAN, must not drive the server through their
// browser: its Origin is refused unless the operator allows it; the server's own page and
// clients that are not browsers (no Origin) are served.
TEST(ConnectionLimitsTest, OnlyTheServersOwnPagesAndAllowedOnesOpenTheWebSocket) {
  testing::ServerProcess server({"--allow-origin", "https://friend.example"});
  const std::string upgrade =
      "Upgrade: websocket\r\nConnection: Upgrade\r\nSec-WebSocket-Version: 13\r\n"
      "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n";
  const std::string own = "Origin: http://127.0.0.1:" + std::to_string(server.http_port()) + "\r\n";
  const std::string switching = "HTTP/1.1 101 Switching Protocols";
  EXPECT_EQ(RawConnection(server.http_port()).get("/ws", upgrade + own), switching);
  EXPECT_EQ(RawConnection(server.http_port()).get("/ws", upgrade), switching);
  EXPECT_EQ(
      RawConnection(server.http_port()).get("/ws", upgrade + "Origin: https://friend.example\r\n"),
      switching);
  EXPECT_EQ(
      RawConnection(server.http_port()).get("/ws", upgrade + "Origin: http://evil.example\r\n"),
      "HTTP/1.1 403 Forbidden");
}

// A site whose name its owner pointed at the server after its page loaded (DNS rebinding) sends
// that name as Origin and Host alike: only names the server is known by pass as its own page.
TEST(ConnectionLimitsTest, APageOfASiteRepointedAtTheServerCannotOpenTheWebSocket) {
  testing::ServerProcess server({"--server-name", "fluid.example.org"});
  const std::string upgrade =
      "Upgrade: websocket\r\nConnection: Upgrade\r\nSec-WebSocket-Version: 13\r\n"
      "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n";
  const std::string port = ":" + std::to_string(server.http_port());
  const auto open = [&](const std::string& name) {
    return RawConnection(server.http_port())
        .get("/ws", upgrade + "Origin: http://" + name + port + "\r\n", name + port);
  };
  EXPECT_EQ(open("evil.example"), "HTTP/1.1 403 Forbidden");
  EXPECT_EQ(open("fluid.example.org"), "HTTP/1.1 101 Switching Protocols");
  EXPECT_EQ(open("localhost"), "HTTP/1.1 101 Switching Protocols");
}

// An upgrade to /ws that is no WebSocket handshake (no key) is answered 400, and its connection
// goes at once: it does not hold its slot until the Hello timeout.
TEST(ConnectionLimitsTest, AFailedWebSocketHandshakeGivesItsSlotBack) {
  testing::ServerProcess server(
      {"--max-connections-per-address", "2", "--hello-timeout", "120"});
  const std::string keyless =
      "Upgrade: websocket\r\nConnection: Upgrade\r\nSec-WebSocket-Version: 13\r\n";
  for (int k = 0; k < 2; ++k) {
    EXPECT_EQ(RawConnection(server.http_port()).get("/ws", keyless), "HTTP/1.1 400 Bad Request");
  }
  std::string answer;
  for (const auto give_up = Clock::now() + seconds(10); answer.empty() && Clock::now() < give_up;) {
    answer = RawConnection(server.http_port()).get("/healthz");
    if (answer.empty()) std::this_thread::sleep_for(milliseconds(100));
  }
  EXPECT_EQ(answer, "HTTP/1.1 200 OK");
}

TEST(ConnectionLimitsTest, ConnectionsOverTheLimitFromOneAddressAreClosedOthersServed) {
  testing::ServerProcess server({"--max-connections-per-address", "4"});
  std::vector<std::unique_ptr<RawConnection>> held;
  for (int k = 0; k < 4; ++k) held.push_back(std::make_unique<RawConnection>(server.http_port()));
  // The fifth is closed as soon as it is accepted; the four are still served.
  RawConnection fifth(server.http_port());
  ASSERT_TRUE(fifth.connected());
  EXPECT_TRUE(fifth.closed_by_server());
  EXPECT_EQ(held[0]->get("/healthz"), "HTTP/1.1 200 OK");
  // One leaves: a new one takes its place, once the server has seen it go (one that comes before
  // is closed like the fifth).
  held.pop_back();
  std::string answer;
  for (const auto give_up = Clock::now() + seconds(10); answer.empty() && Clock::now() < give_up;) {
    std::this_thread::sleep_for(milliseconds(100));
    answer = RawConnection(server.http_port()).get("/healthz");
  }
  EXPECT_EQ(answer, "HTTP/1.1 200 OK");
}

// The same on the plaintext gRPC port: gRPC does not say when it closes a connection, so the
// server finds which have closed when one is over the limit.
TEST(ConnectionLimitsTest, GrpcConnectionsOverTheLimitFromOneAddressAreClosedOthersServed) {
  testing::ServerProcess server({"--max-connections-per-address", "4"});
  const std::string& address = server.grpc_address();
  const int grpc_port = std::stoi(address.substr(address.rfind(':') + 1));
  std::vector<std::unique_ptr<RawConnection>> held;
  // Their reads wait 2 s: below, one is to see nothing.
  for (int k = 0; k < 4; ++k)
    held.push_back(std::make_unique<RawConnection>(grpc_port, seconds(2)));
  std::this_thread::sleep_for(milliseconds(200));
  RawConnection fifth(grpc_port);
  ASSERT_TRUE(fifth.connected());
  EXPECT_TRUE(fifth.closed_by_server());
  EXPECT_FALSE(held[0]->closed_by_server());  // gRPC's SETTINGS, or nothing yet: still open
  // One leaves: a client streams again in its place.
  held.pop_back();
  std::this_thread::sleep_for(milliseconds(500));
  client::StreamClient viewer(client::connect(address), small_session());
  EXPECT_FALSE(viewer.next_frame(seconds(30)) == std::nullopt);
}

TEST(ConnectionLimitsTest, WhenDescriptorsRunOutItWaitsAndServesAgainOnceTheyAreBack) {
  // 96 descriptors in all: connections to the gRPC port (which has no total of its own) take
  // the rest, and the HTTP port can accept nothing. (gRPC 1.51's own acceptor would stop for good
  // here: the server accepts gRPC's connections itself.)
  testing::ServerProcess server({"--max-connections-per-address", "1000"}, 96);
  RawConnection monitor(server.http_port());  // a load balancer's, open before
  ASSERT_EQ(monitor.get("/healthz"), "HTTP/1.1 200 OK");
  auto flood = flood_grpc_port(server);
  EXPECT_EQ(health_once_flooded(monitor), "HTTP/1.1 503 Service Unavailable")
      << "healthy while it cannot accept?";
  {
    RawConnection starved(server.http_port(), milliseconds(1000));
    EXPECT_EQ(starved.get("/healthz"), "") << "answered with no descriptors left?";
  }
  // While starved, the acceptor waits between attempts instead of spinning on the error.
  const double cpu_before = server.cpu_seconds();
  std::this_thread::sleep_for(seconds(2));
  const double cpu_spent = server.cpu_seconds() - cpu_before;
  EXPECT_LT(cpu_spent, 0.5) << "the server spun while out of descriptors";
  flood.clear();
  // Once they are back, new clients are served again within seconds, and it says it is healthy.
  std::string answer;
  const auto freed = Clock::now();
  while (answer != "HTTP/1.1 200 OK" && Clock::now() - freed < seconds(10)) {
    RawConnection client(server.http_port(), milliseconds(500));
    answer = client.get("/healthz");
  }
  EXPECT_EQ(answer, "HTTP/1.1 200 OK");
  std::printf("HTTP served again %.1f s after the descriptors came back\n",
              std::chrono::duration<double>(Clock::now() - freed).count());
  client::StreamClient viewer(client::connect(server.grpc_address()), small_session());
  EXPECT_FALSE(viewer.next_frame(seconds(30)) == std::nullopt)
      << "the gRPC port stayed deaf after the descriptors came back";
  std::printf("gRPC streamed again %.1f s after the descriptors came back\n",
              std::chrono::duration<double>(Clock::now() - freed).count());
}

// The same over TLS: the server's own listener accepts TLS connections too and hands them to
// gRPC (gRPC 1.51's acceptor, left to itself, stopped for good here).
TEST(ConnectionLimitsTest, WhenDescriptorsRunOutUnderTlsItServesAgainOnceTheyAreBack) {
  const auto folder =
      std::filesystem::temp_directory_path() / ("fluidcast-tls-" + std::to_string(::getpid()));
  const server::TlsFiles tls = server::self_signed_certificate(folder, {});
  testing::ServerProcess server({"--tls-cert", tls.certificate.string(), "--tls-key",
                                 tls.key.string(), "--max-connections-per-address", "1000"},
                                96);
  RawConnection monitor(server.http_port());
  ASSERT_EQ(monitor.get("/healthz"), "HTTP/1.1 200 OK");
  auto flood = flood_grpc_port(server);
  EXPECT_EQ(health_once_flooded(monitor), "HTTP/1.1 503 Service Unavailable")
      << "healthy while it cannot accept?";
  flood.clear();
  const auto freed = Clock::now();
  std::string answer;
  while (answer != "HTTP/1.1 200 OK" && Clock::now() - freed < seconds(10)) {
    std::this_thread::sleep_for(milliseconds(100));
    answer = monitor.get("/healthz");
  }
  EXPECT_EQ(answer, "HTTP/1.1 200 OK") << "unhealthy after the descriptors came back";
  std::ifstream certificate(tls.certificate);
  std::stringstream pem;
  pem << certificate.rdbuf();
  grpc::SslCredentialsOptions trust;
  trust.pem_root_certs = pem.str();
  client::StreamClient viewer(
      grpc::CreateChannel(server.grpc_address(), grpc::SslCredentials(trust)), small_session());
  EXPECT_FALSE(viewer.next_frame(seconds(30)) == std::nullopt)
      << "the TLS gRPC port stayed deaf after the descriptors came back";
  std::printf("gRPC over TLS streamed again %.1f s after the descriptors came back\n",
              std::chrono::duration<double>(Clock::now() - freed).count());
  std::filesystem::remove_all(folder);
}

}  // namespace
}  // namespace fluidcast

// The client side of a Stream, for the headless client, the native client and the integration
// tests: connects, says Hello, sends input, and receives frames (acknowledging each one) on a
// reader thread. Measures touch-to-photon latency: from sending an input event to receiving the
// first frame that reflects it.
#pragma once

#include <grpcpp/grpcpp.h>

#include <chrono>
#include <condition_variable>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "fluidcast/v1/fluidcast.grpc.pb.h"

namespace fluidcast::client {

// The stream ended with an error status; what() is the server's message.
class StreamError : public std::runtime_error {
 public:
  explicit StreamError(const grpc::Status& status);
  grpc::StatusCode code() const { return code_; }

 private:
  grpc::StatusCode code_;
};

std::shared_ptr<grpc::Channel> connect(const std::string& server);

class StreamClient {
 public:
  // Opens a stream and sends `hello`; waits for the Welcome (throws StreamError when the server
  // refuses, with its status).
  StreamClient(std::shared_ptr<grpc::Channel> channel, const v1::Hello& hello);
  ~StreamClient();
  StreamClient(const StreamClient&) = delete;
  StreamClient& operator=(const StreamClient&) = delete;

  const v1::Welcome& welcome() const { return welcome_; }

  // Input; each returns the event id it was sent with.
  std::uint64_t pointer(std::uint32_t id, v1::PointerEvent::Phase phase, float x, float y);
  std::uint64_t tilt(float x, float y, float z);
  std::uint64_t command(const v1::Command& command);
  // Any message, as given (for tests of what the server refuses).
  bool send_raw(const v1::ClientMessage& message);

  // The next frame, acknowledged; nothing when none came within `timeout` or the stream ended.
  std::optional<v1::Frame> next_frame(std::chrono::milliseconds timeout);
  // Whether the stream has ended, and how (after it has).
  bool ended() const;
  grpc::Status status() const;
  // Closes the sending side and waits for the server's status.
  grpc::Status finish();
  // Drops the connection without a goodbye, as a phone losing its network does.
  void drop();

  // Touch-to-photon latencies measured so far, milliseconds.
  std::vector<double> latencies_ms() const;

 private:
  std::uint64_t send_input(v1::ClientMessage message);
  void read_loop();

  grpc::ClientContext context_;
  std::unique_ptr<v1::Fluidcast::Stub> stub_;
  std::unique_ptr<grpc::ClientReaderWriter<v1::ClientMessage, v1::ServerMessage>> stream_;
  v1::Welcome welcome_;

  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<v1::Frame> frames_;
  bool ended_ = false, writes_done_ = false;
  grpc::Status status_;
  std::uint64_t next_event_ = 1;
  std::map<std::uint64_t, std::chrono::steady_clock::time_point> unanswered_;
  std::vector<double> latencies_ms_;
  std::mutex write_mutex_;
  std::thread reader_;
};

}  // namespace fluidcast::client

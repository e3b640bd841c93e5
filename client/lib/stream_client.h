// The client side of a Stream, for the headless client, the native client and the integration
// tests: connects, says Hello, sends input, and receives frames (acknowledging each one) on a
// reader thread. Messages go out on a writer thread, so no caller ever waits on the
// network. Measures touch-to-photon latency: from sending an input event to receiving the
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
#include <stop_token>
#include <string>
#include <thread>
#include <vector>

#include "fluid_stream.h"
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

// The session joined and how others can join it, in a line for the terminal.
std::string describe_welcome(const v1::Welcome& welcome);

// Whether a stream that ended with `status` was lost rather than ended by the server on purpose:
// UNAVAILABLE (the server stopped, the network dropped, or drop()), or a stream gRPC cancelled
// when its buffers passed their quota on the server (RESOURCE_EXHAUSTED from a bare RST_STREAM,
// which carries none of the server's sentences: someone else's huge messages, not this viewer's).
bool stream_lost(const grpc::Status& status);

class StreamClient final : public FluidStream {
 public:
  // Opens a stream and sends `hello`; waits for the Welcome (throws StreamError when the server
  // refuses, with its status, and UNAVAILABLE when none comes within `welcome_within`: a server
  // that takes the call and never answers is one that does not answer). Once `stop` is requested
  // it waits no longer, for the connection or the Welcome, nor does a snapshot call under way
  // (CANCELLED): a client closing does not wait on a server that stopped answering.
  static constexpr std::chrono::seconds kWelcomeWithin{30};
  StreamClient(std::shared_ptr<grpc::Channel> channel, const v1::Hello& hello,
               std::chrono::milliseconds welcome_within = kWelcomeWithin,
               std::stop_token stop = {});
  ~StreamClient();
  StreamClient(const StreamClient&) = delete;
  StreamClient& operator=(const StreamClient&) = delete;

  const v1::Welcome& welcome() const override { return welcome_; }
  // Queues the message for the writer thread; 0 once the stream ended or is closing.
  std::uint64_t send(v1::ClientMessage message) override;
  // Any message, as given (for tests of what the server refuses); false when not queued.
  bool send_raw(const v1::ClientMessage& message);
  // Messages waiting at most; more means the server stopped reading, and the stream is dropped
  // (its status then says so).
  static constexpr std::size_t kMaxOutgoing = 1024;

  std::optional<v1::Frame> next_frame(std::chrono::milliseconds timeout) override;
  bool ended() const override;
  std::string end_reason() const override { return status().error_message(); }
  bool lost() const override { return ended() && stream_lost(status()); }
  std::string close() override;
  grpc::Status status() const;
  // Closes the sending side once what is queued is written, and waits for the server's status;
  // each of the two waits is at most kFinishWithin, then the call is cancelled and its status
  // says which wait ran out.
  grpc::Status finish();
  static constexpr std::chrono::seconds kFinishWithin{5};
  // Drops the connection without a goodbye, as a phone losing its network does.
  void drop();

  // The newest state the server sent (after a StateRequest) that was not taken yet, waiting up to
  // `timeout` for one.
  std::optional<v1::Snapshot> take_state(std::chrono::milliseconds timeout);
  // GetSnapshot with the session's view key (any viewer may), and PutSnapshot (needs control,
  // Welcome.access), as calls of their own beside the stream; both throw StreamError.
  v1::Snapshot snapshot() override;
  void load(const v1::Snapshot& snapshot) override;

 private:
  void read_loop();
  void write_loop();
  bool queue(v1::ClientMessage message);  // under write_mutex_
  void cancel_because(std::string why);   // under write_mutex_

  grpc::ClientContext context_;
  std::unique_ptr<v1::Fluidcast::Stub> stub_;
  const std::string token_;  // the Hello's, for the snapshot calls
  const std::stop_token stop_;  // the client closing: a snapshot call under way is cancelled
  std::unique_ptr<grpc::ClientReaderWriter<v1::ClientMessage, v1::ServerMessage>> stream_;
  v1::Welcome welcome_;
  SessionChanges changes_;  // from the reader, into welcome_ in next_frame

  // Frames kept for a caller that reads slower than they come; older ones are dropped.
  FrameQueue frames_{4};
  mutable std::mutex mutex_;
  grpc::Status status_;                // once frames_ is closed
  std::optional<v1::Snapshot> state_;  // under mutex_
  std::condition_variable state_arrived_;

  std::mutex write_mutex_;  // guards what follows, up to the threads
  std::condition_variable write_wanted_;
  std::deque<v1::ClientMessage> outgoing_;
  bool closing_ = false;           // finish(): WritesDone once the queue is written
  bool stopping_ = false;          // the stream ended: the writer stops
  std::string cancelled_because_;  // why we cancelled the call, if we did: the status says so
  bool writer_done_ = false;
  std::thread writer_, reader_;
};

}  // namespace fluidcast::client

#include "stream_client.h"

#include <algorithm>
#include <utility>

#include "fluidcast/v1/wire_sizes.h"

namespace fluidcast::client {
namespace {

constexpr auto kConnectTimeout = std::chrono::seconds(5);
// How often a connection being made looks whether its client is closing.
constexpr auto kStopSeenWithin = std::chrono::milliseconds(50);
constexpr int kReconnectEvery = 500;  // ms

// A snapshot call is given the time the server takes to build it (GetSnapshot) or to load it
// (PutSnapshot: the session's solver is rebuilt), and as long again as its bytes take over a slow
// link: 1 MB/s gives the largest session a server allows (1M particles, 24 MB) half a minute more,
// where fixed deadlines needed 40 Mbit/s.
constexpr auto kSnapshotBuild = std::chrono::seconds(5);
constexpr auto kSnapshotLoad = std::chrono::seconds(10);
constexpr double kSlowLinkBytesPerSecond = 1e6;

std::chrono::system_clock::time_point snapshot_deadline(std::chrono::seconds work,
                                                        std::size_t bytes) {
  const std::chrono::duration<double> moving(static_cast<double>(bytes) / kSlowLinkBytesPerSecond);
  return std::chrono::system_clock::now() + work +
         std::chrono::duration_cast<std::chrono::milliseconds>(moving);
}

}  // namespace
StreamError::StreamError(const grpc::Status& status)
    : std::runtime_error(status.error_message()), code_(status.error_code()) {}

std::shared_ptr<grpc::Channel> connect(const std::string& server) {
  grpc::ChannelArguments arguments;
  arguments.SetInt(GRPC_ARG_KEEPALIVE_TIME_MS, 10000);
  arguments.SetInt(GRPC_ARG_KEEPALIVE_TIMEOUT_MS, 5000);
  // gRPC waits 1 s after a refused connection, then 1.6 times longer each time: within the 5 s a
  // connection is given, a server back from a restart was found up to 2.6 s late. A refused
  // connection on loopback or a LAN costs nothing, so it is tried again every half second.
  arguments.SetInt(GRPC_ARG_INITIAL_RECONNECT_BACKOFF_MS, kReconnectEvery);
  arguments.SetInt(GRPC_ARG_MAX_RECONNECT_BACKOFF_MS, kReconnectEvery);
  arguments.SetMaxReceiveMessageSize(64 << 20);
  return grpc::CreateCustomChannel(server, grpc::InsecureChannelCredentials(), arguments);
}

StreamClient::StreamClient(std::shared_ptr<grpc::Channel> channel, const v1::Hello& hello,
                           std::chrono::milliseconds welcome_within, std::stop_token stop)
    : stub_(v1::Fluidcast::NewStub(channel)), token_(hello.token()), stop_(stop) {
  const grpc::Status closing(grpc::StatusCode::CANCELLED, "the client closed while connecting");
  // A server that cannot be reached is said in seconds, not after gRPC's long backoff.
  const auto give_up = std::chrono::system_clock::now() + kConnectTimeout;
  while (!channel->WaitForConnected(
      std::min(give_up, std::chrono::system_clock::now() + kStopSeenWithin))) {
    if (stop.stop_requested()) throw StreamError(closing);
    if (std::chrono::system_clock::now() >= give_up) {
      throw StreamError(
          grpc::Status(grpc::StatusCode::UNAVAILABLE,
                       "no server answered within 5 s; is fluidcast-server running there?"));
    }
  }
  if (stop.stop_requested()) throw StreamError(closing);  // before a Hello makes a session
  stream_ = stub_->Stream(&context_);
  v1::ClientMessage message;
  *message.mutable_hello() = hello;
  v1::ServerMessage reply;
  // The blocking Write and Read have no deadline of their own: a watchdog cancels them.
  std::mutex waiting;
  std::condition_variable_any answered;
  bool done = false, gave_up = false;
  std::thread watchdog([&] {
    std::unique_lock lock(waiting);
    if (!answered.wait_for(lock, stop, welcome_within, [&] { return done; })) {
      gave_up = true;
      context_.TryCancel();
    }
  });
  const bool welcomed = stream_->Write(message) && stream_->Read(&reply);
  {
    std::lock_guard lock(waiting);
    done = true;
  }
  answered.notify_all();
  watchdog.join();
  if (!welcomed) {
    const grpc::Status status = stream_->Finish();
    if (gave_up && stop.stop_requested()) throw StreamError(closing);
    if (gave_up) {
      throw StreamError(grpc::Status(grpc::StatusCode::UNAVAILABLE,
                                     "the server took the stream but sent no Welcome within " +
                                         std::to_string(welcome_within.count()) + " ms"));
    }
    throw StreamError(status.ok() ? grpc::Status(grpc::StatusCode::UNAVAILABLE,
                                                 "the stream ended before the Welcome")
                                  : status);
  }
  if (!reply.has_welcome()) {
    context_.TryCancel();
    stream_->Finish();
    throw StreamError(
        grpc::Status(grpc::StatusCode::INTERNAL, "the server's first message is not a Welcome"));
  }
  welcome_ = reply.welcome();
  writer_ = std::thread([this] { write_loop(); });
  try {
    reader_ = std::thread([this] { read_loop(); });
  } catch (...) {  // no thread: the writer stops, the call ends, the error goes to the caller
    {
      std::lock_guard lock(write_mutex_);
      stopping_ = true;
    }
    write_wanted_.notify_all();
    writer_.join();
    context_.TryCancel();
    stream_->Finish();
    throw;
  }
}

StreamClient::~StreamClient() {
  if (!ended()) context_.TryCancel();
  if (reader_.joinable()) reader_.join();
}

std::optional<v1::Snapshot> StreamClient::take_state(std::chrono::milliseconds timeout) {
  std::unique_lock lock(mutex_);
  state_arrived_.wait_for(lock, timeout, [this] { return state_.has_value(); });
  return std::exchange(state_, std::nullopt);
}

void StreamClient::read_loop() {
  v1::ServerMessage message;
  while (stream_->Read(&message)) {
    if (message.has_state()) {
      std::lock_guard lock(mutex_);
      state_ = std::move(*message.mutable_state());
      state_arrived_.notify_all();
      continue;
    }
    if (message.has_session()) {
      changes_.arrived(std::move(*message.mutable_session()));
      continue;
    }
    if (!message.has_frame()) continue;
    v1::ClientMessage ack;
    ack.mutable_ack()->set_sequence(message.frame().sequence());
    ack.mutable_ack()->set_client_receive_time_us(
        std::chrono::duration_cast<std::chrono::microseconds>(
            std::chrono::system_clock::now().time_since_epoch())
            .count());
    {
      std::lock_guard lock(write_mutex_);
      queue(std::move(ack));
    }
    latency_.frame_reflects(message.frame().input_event_id());
    frames_.push(std::move(*message.mutable_frame()));
  }
  // The call is over, so a write still in progress fails at once; Finish comes after it.
  std::string cancelled_because;
  {
    std::lock_guard lock(write_mutex_);
    stopping_ = true;
    cancelled_because = cancelled_because_;
  }
  write_wanted_.notify_all();
  writer_.join();
  grpc::Status status = stream_->Finish();
  if (!cancelled_because.empty() && status.error_code() == grpc::StatusCode::CANCELLED) {
    status = grpc::Status(grpc::StatusCode::UNAVAILABLE, cancelled_because);  // our cancel
  }
  {
    std::lock_guard lock(mutex_);
    status_ = status;
  }
  frames_.close();
}

void StreamClient::write_loop() {
  std::unique_lock lock(write_mutex_);
  struct Done {  // however the loop ends, finish() hears of it (under the lock)
    StreamClient* client;
    std::unique_lock<std::mutex>& lock;
    ~Done() {
      if (!lock.owns_lock()) lock.lock();
      client->writer_done_ = true;
      client->write_wanted_.notify_all();
    }
  } done{this, lock};
  for (;;) {
    write_wanted_.wait(lock, [this] { return stopping_ || closing_ || !outgoing_.empty(); });
    if (stopping_) return;
    if (outgoing_.empty()) {  // closing, everything written
      lock.unlock();
      stream_->WritesDone();
      return;
    }
    const v1::ClientMessage message = std::move(outgoing_.front());
    outgoing_.pop_front();
    lock.unlock();
    const bool written = stream_->Write(message);
    lock.lock();
    if (!written) {  // the stream broke: the reader sees its end
      stopping_ = true;
      return;
    }
  }
}

bool StreamClient::queue(v1::ClientMessage message) {
  if (stopping_ || closing_ || !cancelled_because_.empty()) return false;
  if (outgoing_.size() >= kMaxOutgoing) {
    cancel_because("the server stopped reading (" + std::to_string(kMaxOutgoing) +
                   " messages waiting to be sent)");
    return false;
  }
  outgoing_.push_back(std::move(message));
  write_wanted_.notify_one();
  return true;
}

std::uint64_t StreamClient::send(v1::ClientMessage message) {
  std::lock_guard lock(write_mutex_);
  if (stopping_ || closing_ || !cancelled_because_.empty()) return 0;
  const std::uint64_t id = latency_.sent();
  message.set_event_id(id);
  return queue(std::move(message)) ? id : 0;
}

bool StreamClient::send_raw(const v1::ClientMessage& message) {
  std::lock_guard lock(write_mutex_);
  return queue(message);
}

std::optional<v1::Frame> StreamClient::next_frame(std::chrono::milliseconds timeout) {
  std::optional<v1::Frame> frame = frames_.pop(timeout);
  changes_.apply_to(welcome_);
  return frame;
}

bool StreamClient::ended() const { return frames_.closed(); }

bool stream_lost(const grpc::Status& status) {
  return status.error_code() == grpc::StatusCode::UNAVAILABLE ||
         (status.error_code() == grpc::StatusCode::RESOURCE_EXHAUSTED &&
          status.error_message().starts_with("Received RST_STREAM"));
}

grpc::Status StreamClient::status() const {
  std::lock_guard lock(mutex_);
  return status_;
}

grpc::Status StreamClient::finish() {
  {
    std::unique_lock lock(write_mutex_);
    closing_ = true;
    write_wanted_.notify_all();
    if (!write_wanted_.wait_for(lock, kFinishWithin, [this] { return writer_done_; })) {
      cancel_because("the server stopped reading (what was sent is not written after " +
                     std::to_string(kFinishWithin.count()) + " s)");
    }
  }
  if (!frames_.wait_closed(kFinishWithin)) {
    std::lock_guard lock(write_mutex_);
    cancel_because("the server did not end the stream within " +
                   std::to_string(kFinishWithin.count()) + " s");
  }
  if (reader_.joinable()) reader_.join();
  return status();
}

void StreamClient::cancel_because(std::string why) {
  if (cancelled_because_.empty()) cancelled_because_ = std::move(why);
  context_.TryCancel();
}

void StreamClient::drop() {
  {
    std::lock_guard lock(write_mutex_);
    cancel_because("the connection was dropped");
  }
  if (reader_.joinable()) reader_.join();
}

std::string StreamClient::close() {
  const grpc::Status status = ended() ? this->status() : finish();
  return status.ok() ? std::string() : status.error_message();
}

v1::Snapshot StreamClient::snapshot() {
  grpc::ClientContext context;
  // The session may have grown since the Welcome: as large as the server allows.
  const std::size_t largest = welcome_.limits().max_particles();
  context.set_deadline(snapshot_deadline(kSnapshotBuild, largest * v1::kSnapshotBytesPerParticle));
  v1::SnapshotRequest request;
  request.set_token(token_);
  request.set_key(welcome_.access().view_key());
  v1::Snapshot snapshot;
  const std::stop_callback cancel(stop_, [&context] { context.TryCancel(); });
  const grpc::Status status = stub_->GetSnapshot(&context, request, &snapshot);
  if (!status.ok()) throw StreamError(status);
  return snapshot;
}

std::string describe_welcome(const v1::Welcome& welcome) {
  const v1::Access& access = welcome.access();
  std::string line = "session " + welcome.session_id() + ", viewer " +
                     std::to_string(welcome.viewer_id()) + ", " +
                     std::to_string(welcome.state().particles()) + " particles; ";
  line += access.control() ? "you control it; to play along: --join " + access.control_key() +
                                 ", to watch: --join " + access.view_key()
                           : "you watch it; to watch along: --join " + access.view_key();
  return line;
}

void StreamClient::load(const v1::Snapshot& snapshot) {
  grpc::ClientContext context;
  v1::PutSnapshotRequest request;
  request.set_token(token_);
  request.set_key(welcome_.access().control_key());
  *request.mutable_snapshot() = snapshot;
  context.set_deadline(snapshot_deadline(kSnapshotLoad, request.ByteSizeLong()));
  v1::PutSnapshotReply reply;
  const std::stop_callback cancel(stop_, [&context] { context.TryCancel(); });
  const grpc::Status status = stub_->PutSnapshot(&context, request, &reply);
  if (!status.ok()) throw StreamError(status);
}

}  // namespace fluidcast::client

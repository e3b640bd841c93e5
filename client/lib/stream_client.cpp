#include "stream_client.h"

namespace fluidcast::client {
namespace {

using Clock = std::chrono::steady_clock;
// Frames kept for a caller that reads slower than they come; older ones are dropped.
constexpr std::size_t kKeptFrames = 4;
// Inputs awaiting a frame, and latencies kept: the newest.
constexpr std::size_t kKeptInputs = 1024;
constexpr std::size_t kKeptLatencies = 100000;

}  // namespace

StreamError::StreamError(const grpc::Status& status)
    : std::runtime_error(status.error_message()), code_(status.error_code()) {}

std::shared_ptr<grpc::Channel> connect(const std::string& server) {
  grpc::ChannelArguments arguments;
  arguments.SetInt(GRPC_ARG_KEEPALIVE_TIME_MS, 10000);
  arguments.SetInt(GRPC_ARG_KEEPALIVE_TIMEOUT_MS, 5000);
  arguments.SetMaxReceiveMessageSize(64 << 20);
  return grpc::CreateCustomChannel(server, grpc::InsecureChannelCredentials(), arguments);
}

StreamClient::StreamClient(std::shared_ptr<grpc::Channel> channel, const v1::Hello& hello)
    : stub_(v1::Fluidcast::NewStub(channel)) {
  stream_ = stub_->Stream(&context_);
  v1::ClientMessage message;
  *message.mutable_hello() = hello;
  v1::ServerMessage reply;
  if (!stream_->Write(message) || !stream_->Read(&reply)) {
    const grpc::Status status = stream_->Finish();
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
  reader_ = std::thread([this] { read_loop(); });
}

StreamClient::~StreamClient() {
  if (!ended()) context_.TryCancel();
  if (reader_.joinable()) reader_.join();
}

void StreamClient::read_loop() {
  v1::ServerMessage message;
  while (stream_->Read(&message)) {
    if (!message.has_frame()) continue;
    const auto now = Clock::now();
    v1::ClientMessage ack;
    ack.mutable_ack()->set_sequence(message.frame().sequence());
    ack.mutable_ack()->set_client_receive_time_us(
        std::chrono::duration_cast<std::chrono::microseconds>(
            std::chrono::system_clock::now().time_since_epoch())
            .count());
    {
      std::lock_guard lock(write_mutex_);
      if (!writes_done_) stream_->Write(ack);
    }
    std::lock_guard lock(mutex_);
    const std::uint64_t reflected = message.frame().input_event_id();
    for (auto it = unanswered_.begin(); it != unanswered_.end() && it->first <= reflected;) {
      latencies_ms_.push_back(std::chrono::duration<double, std::milli>(now - it->second).count());
      it = unanswered_.erase(it);
    }
    if (latencies_ms_.size() > kKeptLatencies) {
      latencies_ms_.erase(latencies_ms_.begin(), latencies_ms_.begin() + kKeptLatencies / 2);
    }
    frames_.push_back(std::move(*message.mutable_frame()));
    while (frames_.size() > kKeptFrames) frames_.pop_front();
    changed_.notify_all();
  }
  const grpc::Status status = stream_->Finish();
  std::lock_guard lock(mutex_);
  status_ = status;
  ended_ = true;
  changed_.notify_all();
}

std::uint64_t StreamClient::send_input(v1::ClientMessage message) {
  std::lock_guard write_lock(write_mutex_);
  std::uint64_t id;
  {
    std::lock_guard lock(mutex_);
    if (ended_) return 0;
    id = next_event_++;
    unanswered_[id] = Clock::now();
    if (unanswered_.size() > kKeptInputs) unanswered_.erase(unanswered_.begin());
  }
  message.set_event_id(id);
  if (!writes_done_) stream_->Write(message);
  return id;
}

std::uint64_t StreamClient::pointer(std::uint32_t id, v1::PointerEvent::Phase phase, float x,
                                    float y) {
  v1::ClientMessage message;
  v1::PointerEvent& event = *message.mutable_pointer();
  event.set_pointer_id(id);
  event.set_phase(phase);
  event.set_x(x);
  event.set_y(y);
  return send_input(std::move(message));
}

std::uint64_t StreamClient::tilt(float x, float y, float z) {
  v1::ClientMessage message;
  message.mutable_tilt()->set_x(x);
  message.mutable_tilt()->set_y(y);
  message.mutable_tilt()->set_z(z);
  return send_input(std::move(message));
}

std::uint64_t StreamClient::command(const v1::Command& command) {
  v1::ClientMessage message;
  *message.mutable_command() = command;
  return send_input(std::move(message));
}

bool StreamClient::send_raw(const v1::ClientMessage& message) {
  std::lock_guard lock(write_mutex_);
  return !writes_done_ && stream_->Write(message);
}

std::optional<v1::Frame> StreamClient::next_frame(std::chrono::milliseconds timeout) {
  std::unique_lock lock(mutex_);
  changed_.wait_for(lock, timeout, [this] { return !frames_.empty() || ended_; });
  if (frames_.empty()) return std::nullopt;
  v1::Frame frame = std::move(frames_.front());
  frames_.pop_front();
  return frame;
}

bool StreamClient::ended() const {
  std::lock_guard lock(mutex_);
  return ended_;
}

grpc::Status StreamClient::status() const {
  std::lock_guard lock(mutex_);
  return status_;
}

grpc::Status StreamClient::finish() {
  {
    std::lock_guard lock(write_mutex_);
    if (!writes_done_) {
      writes_done_ = true;
      stream_->WritesDone();
    }
  }
  if (reader_.joinable()) reader_.join();
  return status();
}

void StreamClient::drop() {
  context_.TryCancel();
  if (reader_.joinable()) reader_.join();
}

std::vector<double> StreamClient::latencies_ms() const {
  std::lock_guard lock(mutex_);
  return latencies_ms_;
}

}  // namespace fluidcast::client

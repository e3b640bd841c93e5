#include "local_stream.h"

#include <future>
#include <stdexcept>

#include "session/validation.h"

namespace fluidcast::client {

// Frames from the in-process session: the newest few, as a remote stream keeps them.
class LocalStream::Sink final : public server::ViewerSink {
 public:
  FrameQueue frames{2};
  SessionChanges changes;  // into the Welcome in next_frame

  bool deliver(std::shared_ptr<const v1::ServerMessage> message) override {
    if (message->has_frame()) {
      frames.push(message->frame());
      return true;
    }
    if (message->has_session()) {
      changes.arrived(message->session());
      return true;
    }
    std::lock_guard lock(mutex_);
    if (message->has_welcome()) welcome_ = message->welcome();
    changed_.notify_all();
    return true;
  }
  void end(const server::Refusal& why) override {
    {
      std::lock_guard lock(mutex_);
      ended_ = why.what();
      changed_.notify_all();
    }
    frames.close();
  }

  std::optional<v1::Welcome> wait_welcome(std::chrono::seconds timeout) {
    std::unique_lock lock(mutex_);
    changed_.wait_for(lock, timeout, [this] { return welcome_.has_value() || ended_; });
    return welcome_;
  }
  std::optional<std::string> ended() const {
    std::lock_guard lock(mutex_);
    return ended_;
  }

 private:
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::optional<v1::Welcome> welcome_;
  std::optional<std::string> ended_;
};

namespace {

server::ServerLimits local_limits(std::uint32_t max_particles) {
  server::ServerLimits limits;
  limits.max_sessions = 1;
  limits.max_particles = max_particles;
  limits.default_particles = std::min<std::uint32_t>(4000, max_particles);
  limits.max_viewers_per_session = 1;
  // The one person here may leave the fluid alone as long as they like (and a warm standby only
  // ever takes snapshots): an idle session is the server's concern, for its shared GPU.
  limits.idle_timeout = std::chrono::seconds(0);
  return limits;
}

}  // namespace

LocalStream::LocalStream(v1::Hello hello, std::uint32_t max_particles)
    : sink_(std::make_shared<Sink>()) {
  const std::uint32_t asked = hello.create().particles();
  if (asked > max_particles) {
    throw std::invalid_argument("local mode simulates at most " + std::to_string(max_particles) +
                                " particles here (--max-local-particles); " +
                                std::to_string(asked) + " asked for");
  }
  if (hello.quality().renderer().empty()) hello.mutable_quality()->set_renderer(kDefaultRenderer);
  v1::ClientMessage message;
  *message.mutable_hello() = hello;
  const server::ServerLimits limits = local_limits(max_particles);
  server::validate_hello(message, limits, std::nullopt);
  // A hardware device simulates on the GPU; lavapipe renders only (the CPU solver is faster).
  hub_ = std::make_unique<server::SessionHub>(context_, context_.info().hardware(), limits,
                                              std::nullopt, metrics_);
  std::promise<server::SessionHub::Opened> opened;
  hub_->open(hello, "this process", sink_,
             [&opened](server::SessionHub::Opened result) { opened.set_value(std::move(result)); });
  server::SessionHub::Opened result = opened.get_future().get();
  if (result.refusal) throw *result.refusal;
  viewer_ = std::move(result.viewer);
  const auto welcome = sink_->wait_welcome(std::chrono::seconds(30));
  if (!welcome) throw std::runtime_error("the local session did not start");
  welcome_ = *welcome;
}

LocalStream::~LocalStream() {
  if (viewer_) viewer_->leave(server::Departure::left);
  viewer_.reset();
  hub_.reset();  // stops the worker: the session's GPU objects go before the context
}

std::uint64_t LocalStream::send(v1::ClientMessage message) {
  if (ended()) return 0;
  server::validate_event(message, hub_->limits(),
                         server::Access::control);  // it created the session
  if (message.has_command() && message.command().has_quality() &&
      message.command().quality().renderer().empty()) {
    message.mutable_command()->mutable_quality()->set_renderer(kDefaultRenderer);
  }
  const std::uint64_t id = latency_.sent();
  message.set_event_id(id);
  viewer_->post(std::move(message));
  return id;
}

std::optional<v1::Frame> LocalStream::next_frame(std::chrono::milliseconds timeout) {
  auto frame = sink_->frames.pop(timeout);
  sink_->changes.apply_to(welcome_);
  if (frame) {
    latency_.frame_reflects(frame->input_event_id());
    v1::ClientMessage ack;
    ack.mutable_ack()->set_sequence(frame->sequence());
    viewer_->post(std::move(ack));
  }
  return frame;
}

bool LocalStream::ended() const { return sink_->ended().has_value(); }

std::string LocalStream::end_reason() const { return sink_->ended().value_or(""); }

std::string LocalStream::close() {
  const std::string why = end_reason();
  viewer_->leave(server::Departure::left);
  return why;
}

v1::Snapshot LocalStream::snapshot() {
  std::promise<v1::Snapshot> result;
  hub_->snapshot(
      welcome_.access().control_key(),
      [&result](std::optional<v1::Snapshot> snapshot, std::optional<server::Refusal> refusal) {
        if (refusal) {
          result.set_exception(std::make_exception_ptr(*refusal));
        } else {
          result.set_value(std::move(*snapshot));
        }
      });
  return result.get_future().get();
}

void LocalStream::load(const v1::Snapshot& snapshot) {
  std::promise<void> result;
  // Not a copy: read until the result, which this waits for.
  hub_->load(welcome_.access().control_key(),
             std::shared_ptr<const v1::Snapshot>(std::shared_ptr<void>(), &snapshot),
             [&result](std::uint32_t, std::optional<server::Refusal> refusal) {
               if (refusal) {
                 result.set_exception(std::make_exception_ptr(*refusal));
               } else {
                 result.set_value();
               }
             });
  result.get_future().get();
}

}  // namespace fluidcast::client

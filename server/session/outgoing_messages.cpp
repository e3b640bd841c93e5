#include "outgoing_messages.h"

namespace fluidcast::server {

bool OutgoingMessages::push(std::shared_ptr<const v1::ServerMessage> message) {
  if (message->has_state()) {
    if (!frames_stopped_) state_ = std::move(message);
    return true;
  }
  if (message->has_session()) {
    if (frames_stopped_) return true;
    session_ = std::move(message);
    state_.reset();  // of the session before the change: a client would keep it as the newest
    return true;
  }
  if (!message->has_frame()) {
    control_.push_back(std::move(message));
    return true;
  }
  if (frames_stopped_ || message->frame().sequence() <= newest_sequence_) return false;
  newest_sequence_ = message->frame().sequence();
  const bool replaced = frame_ != nullptr;
  frame_ = std::move(message);
  frame_pushed_ = Clock::now();
  return !replaced;
}

std::shared_ptr<const v1::ServerMessage> OutgoingMessages::next() {
  writing_frame_pushed_.reset();
  if (!control_.empty()) {
    auto message = std::move(control_.front());
    control_.pop_front();
    return message;
  }
  if (session_) return std::move(session_);
  if (state_) return std::move(state_);
  if (frame_) writing_frame_pushed_ = frame_pushed_;
  return std::move(frame_);
}

std::optional<double> OutgoingMessages::written() {
  if (!writing_frame_pushed_) return std::nullopt;
  const double ms =
      std::chrono::duration<double, std::milli>(Clock::now() - *writing_frame_pushed_).count();
  writing_frame_pushed_.reset();
  return ms;
}

void OutgoingMessages::stop_frames() {
  frames_stopped_ = true;
  frame_.reset();
  session_.reset();
  state_.reset();
}

}  // namespace fluidcast::server

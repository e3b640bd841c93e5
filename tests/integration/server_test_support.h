// What the server's integration tests share: a small Hello, a frame or the end of a stream,
// and a refusal's status.
#pragma once

#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <stdexcept>
#include <string>

#include "server_process.h"
#include "stream_client.h"

namespace fluidcast {

using client::StreamClient;
using client::StreamError;
using std::chrono::milliseconds;
using std::chrono::seconds;

// Small enough for two cores: a fast session, a small frame.
inline v1::Hello small_hello(std::uint32_t particles = 1000) {
  v1::Hello hello;
  hello.mutable_viewport()->set_width(160);
  hello.mutable_viewport()->set_height(120);
  hello.mutable_create()->set_scene("dam_break");
  hello.mutable_create()->set_particles(particles);
  return hello;
}

inline v1::Frame frame_from(StreamClient& stream) {
  auto frame = stream.next_frame(seconds(30));
  if (!frame) throw std::runtime_error("no frame within 30 s: " + stream.status().error_message());
  return *frame;
}

// Sends one message after a valid Hello, and returns how the server ended the stream.
inline grpc::Status status_after(const std::string& address, const v1::ClientMessage& message) {
  StreamClient stream(client::connect(address), small_hello());
  stream.send_raw(message);
  for (int k = 0; k < 300 && !stream.ended(); ++k) stream.next_frame(milliseconds(100));
  return stream.ended() ? stream.status() : grpc::Status(grpc::StatusCode::OK, "still streaming");
}

inline grpc::StatusCode refusal_of(const std::string& address, const v1::Hello& hello) {
  try {
    StreamClient stream(client::connect(address), hello);
  } catch (const StreamError& e) {
    std::printf("refused: %s\n", e.what());
    return e.code();
  }
  return grpc::StatusCode::OK;
}

}  // namespace fluidcast

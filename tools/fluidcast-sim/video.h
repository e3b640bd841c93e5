// fluidcast-sim --video: frames piped as raw RGBA into ffmpeg, which writes an H.264 file.
#pragma once

#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>

#include "fluidcast/codec/image.h"

namespace fluidcast::tools {

// Where ffmpeg is on PATH, if it is.
std::optional<std::filesystem::path> find_ffmpeg();

class VideoPipe {
 public:
  // Starts ffmpeg. Throws std::runtime_error when it cannot be started.
  VideoPipe(const std::filesystem::path& output, int width, int height, double frames_per_second);
  // Closes the pipe if finish() was not called (the file may then be incomplete).
  ~VideoPipe();
  VideoPipe(const VideoPipe&) = delete;
  VideoPipe& operator=(const VideoPipe&) = delete;

  // Throws std::runtime_error when ffmpeg has gone (a full disk, say).
  void write(const codec::ImageRgba& frame);
  // Waits for ffmpeg; throws std::runtime_error naming the file when ffmpeg failed.
  void finish();

 private:
  std::filesystem::path output_;
  int width_, height_;
  std::FILE* pipe_ = nullptr;
};

}  // namespace fluidcast::tools

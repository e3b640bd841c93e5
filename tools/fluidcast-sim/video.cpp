#include "video.h"

#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <cstdlib>
#include <stdexcept>

namespace fluidcast::tools {
namespace {

std::string quoted(const std::string& text) {
  std::string out = "'";
  for (char c : text) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

}  // namespace

std::optional<std::filesystem::path> find_ffmpeg() {
  const char* path = std::getenv("PATH");
  if (!path) return std::nullopt;
  const std::string folders = path;
  for (std::size_t start = 0; start <= folders.size();) {
    const std::size_t end = std::min(folders.find(':', start), folders.size());
    const std::filesystem::path candidate =
        std::filesystem::path(folders.substr(start, end - start)) / "ffmpeg";
    if (::access(candidate.c_str(), X_OK) == 0) return candidate;
    start = end + 1;
  }
  return std::nullopt;
}

VideoPipe::VideoPipe(const std::filesystem::path& output, int width, int height,
                     double frames_per_second)
    : output_(output), width_(width), height_(height) {
  const auto ffmpeg = find_ffmpeg();
  if (!ffmpeg)
    throw std::runtime_error("--video: ffmpeg is not installed (apt-get install ffmpeg)");
  // H.264 in 4:2:0 wants even sizes: pad by a pixel where needed.
  const std::string command =
      quoted(ffmpeg->string()) + " -hide_banner -loglevel error -y -f rawvideo -pix_fmt rgba -s " +
      std::to_string(width) + "x" + std::to_string(height) + " -framerate " +
      std::to_string(frames_per_second) + " -i - -vf " + quoted("pad=ceil(iw/2)*2:ceil(ih/2)*2") +
      " -c:v libx264 -pix_fmt yuv420p -movflags +faststart " +
      // A path starting with '-' would read as an option.
      quoted((output.string().rfind('-', 0) == 0 ? "./" : "") + output.string());
  // A vanished ffmpeg must give an error on write, not end this process.
  std::signal(SIGPIPE, SIG_IGN);
  pipe_ = ::popen(command.c_str(), "w");
  if (!pipe_) throw std::runtime_error("--video: cannot start ffmpeg");
}

VideoPipe::~VideoPipe() {
  if (pipe_) ::pclose(pipe_);
}

void VideoPipe::write(const codec::ImageRgba& frame) {
  if (frame.width != width_ || frame.height != height_) {
    throw std::logic_error("--video: a frame of another size");
  }
  if (std::fwrite(frame.pixels.data(), 1, frame.pixels.size(), pipe_) != frame.pixels.size()) {
    throw std::runtime_error("--video: ffmpeg stopped taking frames for " + output_.string());
  }
}

void VideoPipe::finish() {
  if (!pipe_) return;
  const int status = ::pclose(pipe_);
  pipe_ = nullptr;
  if (status == -1 || !WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    throw std::runtime_error("--video: ffmpeg failed to write " + output_.string());
  }
}

}  // namespace fluidcast::tools

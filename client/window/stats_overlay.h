// The window's stats overlay: a few lines of text in a translucent box at the top left, each
// wrapped to the window's width (SDL_ttf, DejaVu Sans Mono from Debian's fonts-dejavu-core).
// Without the font it says so once and stays off; the window title carries the same figures.
#pragma once

#include <SDL.h>

#include <memory>
#include <string>
#include <vector>

namespace fluidcast::client {

class StatsOverlay {
 public:
  explicit StatsOverlay(SDL_Renderer* renderer);
  ~StatsOverlay();
  StatsOverlay(const StatsOverlay&) = delete;
  StatsOverlay& operator=(const StatsOverlay&) = delete;

  void set_lines(const std::vector<std::string>& lines);
  void draw() const;
  void toggle() { visible_ = !visible_; }

 private:
  struct Line {
    std::unique_ptr<SDL_Texture, void (*)(SDL_Texture*)> texture;
    int width, height;
  };
  SDL_Renderer* renderer_;
  struct Font;
  std::unique_ptr<Font> font_;
  std::vector<Line> lines_;
  bool visible_ = true;
};

}  // namespace fluidcast::client

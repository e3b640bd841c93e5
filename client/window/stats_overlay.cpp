#include "stats_overlay.h"

#include <SDL_ttf.h>

#include <algorithm>
#include <cstdio>

namespace fluidcast::client {

struct StatsOverlay::Font {
  TTF_Font* font = nullptr;
  ~Font() {
    if (font) TTF_CloseFont(font);
    TTF_Quit();
  }
};

StatsOverlay::StatsOverlay(SDL_Renderer* renderer) : renderer_(renderer) {
  if (TTF_Init() != 0) {
    std::fprintf(stderr, "fluidcast-client: no stats overlay: SDL_ttf: %s\n", TTF_GetError());
    return;
  }
  font_ = std::make_unique<Font>();
  font_->font = TTF_OpenFont(FLUIDCAST_OVERLAY_FONT, 14);
  if (!font_->font) {
    std::fprintf(stderr, "fluidcast-client: no stats overlay: %s: %s (install fonts-dejavu-core)\n",
                 FLUIDCAST_OVERLAY_FONT, TTF_GetError());
    font_.reset();
  }
}

StatsOverlay::~StatsOverlay() = default;

void StatsOverlay::set_lines(const std::vector<std::string>& lines) {
  lines_.clear();
  if (!font_ || !visible_) return;
  // A line longer than the window goes on below (a reason the fluid did not open, say).
  int window_width = 0, window_height = 0;
  SDL_GetRendererOutputSize(renderer_, &window_width, &window_height);
  const Uint32 wrap = static_cast<Uint32>(std::max(100, window_width - 24));
  for (const std::string& text : lines) {
    SDL_Surface* surface = TTF_RenderUTF8_Blended_Wrapped(font_->font, text.c_str(),
                                                          SDL_Color{235, 235, 235, 255}, wrap);
    if (!surface) continue;
    SDL_Texture* texture = SDL_CreateTextureFromSurface(renderer_, surface);
    const int width = surface->w, height = surface->h;
    SDL_FreeSurface(surface);
    if (texture) lines_.push_back({{texture, SDL_DestroyTexture}, width, height});
  }
}

void StatsOverlay::draw() const {
  if (!visible_ || lines_.empty()) return;
  int width = 0, height = 0;
  for (const Line& line : lines_) {
    width = std::max(width, line.width);
    height += line.height;
  }
  SDL_SetRenderDrawBlendMode(renderer_, SDL_BLENDMODE_BLEND);
  SDL_SetRenderDrawColor(renderer_, 0, 0, 0, 150);
  const SDL_Rect box{6, 6, width + 12, height + 10};
  SDL_RenderFillRect(renderer_, &box);
  int y = 11;
  for (const Line& line : lines_) {
    const SDL_Rect where{12, y, line.width, line.height};
    SDL_RenderCopy(renderer_, line.texture.get(), nullptr, &where);
    y += line.height;
  }
}

}  // namespace fluidcast::client

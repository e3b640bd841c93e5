#include "window_client.h"

#include <SDL.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <future>
#include <map>
#include <memory>
#include <stop_token>

#include "fluidcast/codec/jpeg.h"
#include "fluidcast/codec/png.h"
#include "handoff_sides.h"
#include "stats_overlay.h"
#include "stream_client.h"

namespace fluidcast::client {
namespace {

using Clock = std::chrono::steady_clock;
// Pointer moves sent per finger at most: the server limits input events per second.
constexpr auto kMoveInterval = std::chrono::milliseconds(16);

// The window's close button (or SDL's SIGINT and SIGTERM), Esc or q.
bool asks_to_quit(const SDL_Event& event) {
  return event.type == SDL_QUIT ||
         (event.type == SDL_KEYDOWN &&
          (event.key.keysym.sym == SDLK_ESCAPE || event.key.keysym.sym == SDLK_q));
}

// Owns an SDL object.
template <typename T, void (*Destroy)(T*)>
struct SdlDeleter {
  void operator()(T* p) const { Destroy(p); }
};
using Window = std::unique_ptr<SDL_Window, SdlDeleter<SDL_Window, SDL_DestroyWindow>>;
using Renderer = std::unique_ptr<SDL_Renderer, SdlDeleter<SDL_Renderer, SDL_DestroyRenderer>>;
using Texture = std::unique_ptr<SDL_Texture, SdlDeleter<SDL_Texture, SDL_DestroyTexture>>;
using Sensor = std::unique_ptr<SDL_Sensor, SdlDeleter<SDL_Sensor, SDL_SensorClose>>;

struct SdlLibrary {
  SdlLibrary() {
    if (SDL_Init(SDL_INIT_VIDEO | SDL_INIT_EVENTS | SDL_INIT_SENSOR) != 0) {
      throw std::runtime_error(std::string("SDL cannot start: ") + SDL_GetError() +
                               " (no display? run it under a desktop, or use --headless)");
    }
    // Without a display SDL falls back to drivers that show nothing: a window nobody sees.
    // (Chosen on purpose through SDL_VIDEODRIVER, they are left alone.)
    const std::string driver = SDL_GetCurrentVideoDriver() ? SDL_GetCurrentVideoDriver() : "";
    const char* asked = std::getenv("SDL_VIDEODRIVER");
    if ((driver == "offscreen" || driver == "dummy") && !(asked && driver == asked)) {
      SDL_Quit();
      throw std::runtime_error("no display: SDL found none to open a window on (only its " +
                               driver + " driver); run it on a desktop, or use --headless");
    }
  }
  ~SdlLibrary() { SDL_Quit(); }
};

// What the window shows, and where it comes from.
class Client {
 public:
  explicit Client(const WindowOptions& options) : options_(options) {}

  int run();

 private:
  void open();
  void handle(const SDL_Event& event);
  // The window's size, to the stream: the frames it asks for.
  void send_viewport();
  void handle_key(SDL_Keycode key);
  void handle_finger(const SDL_TouchFingerEvent& finger, Uint32 type);
  void pointer(std::uint32_t id, v1::PointerEvent::Phase phase, float window_x, float window_y);
  // How often each pointer's moves go: kMoveInterval, and for all of them together at most half
  // the server's input rate (a hand on a touch screen, 10 fingers' 600 moves a second, would
  // pass its 400 and end the stream).
  Clock::duration move_interval() const;
  // Whether this viewer may change the fluid (it joined with a view key: no).
  bool controls() const { return stream_ && stream_->welcome().access().control(); }
  // The mouse takes the last pointer id the server allows (Welcome.rules), fingers those below;
  // kept while no stream says it (a handoff's gap), so that a release then lifts what it pressed.
  std::uint32_t mouse_pointer() {
    if (stream_ && stream_->welcome().rules().pointer_ids() > 0) {
      mouse_pointer_ = stream_->welcome().rules().pointer_ids() - 1;
    }
    return mouse_pointer_;
  }
  void show(const v1::Frame& frame);
  void draw();
  void update_title(Clock::time_point now);
  std::string status() const;
  void complain(std::string trouble);
  // The window as drawn, as --screenshot's PNG: read before it is presented, after which the
  // renderer's buffer is undefined.
  void write_screenshot() const;
  v1::Hello hello_for_window() const;
  // Why the fluid did not open, in the window and its title, until it is closed (or --seconds);
  // --screenshot shows it.
  void say_until_closed(const std::string& why);

  WindowOptions options_;
  SdlLibrary sdl_;  // first in, last out: SDL_Quit after every SDL object is gone
  Window window_;
  Renderer renderer_;
  Texture texture_;
  int frame_width_ = 0, frame_height_ = 0;
  std::unique_ptr<StatsOverlay> overlay_;
  v1::Frame last_frame_;  // without its JPEG: what the overlay reports
  Sensor accelerometer_;

  std::stop_source closing_;  // requested when the window closes while the fluid opens
  std::unique_ptr<HandoffStream> stream_;
  // The newest input refused or frame not shown, said beside the stream's status for a while.
  std::string trouble_;
  Clock::time_point trouble_until_{};
  std::map<SDL_FingerID, std::uint32_t> fingers_;
  std::map<std::uint32_t, Clock::time_point> last_move_;
  std::uint32_t mouse_pointer_ = 0;
  bool screenshot_wanted_ = false;  // by F12, or at the end
  Clock::time_point last_tilt_{}, last_title_{};
  std::size_t frames_ = 0;
  std::vector<std::pair<Clock::time_point, std::size_t>> recent_frames_;  // arrival, JPEG bytes
  bool quit_ = false;
  Clock::time_point end_ = Clock::time_point::max();  // --seconds after the start
  int renderer_choice_ = 0;
};

v1::Hello Client::hello_for_window() const {
  v1::Hello hello = options_.hello;
  int width = 0, height = 0;
  SDL_GetRendererOutputSize(renderer_.get(), &width, &height);
  const double scale = std::min({1.0, double(kMaxViewportWidth) / std::max(1, width),
                                 double(kMaxViewportHeight) / std::max(1, height)});
  hello.mutable_viewport()->set_width(static_cast<std::uint32_t>(std::max(1.0, width * scale)));
  hello.mutable_viewport()->set_height(static_cast<std::uint32_t>(std::max(1.0, height * scale)));
  return hello;
}

// The fluid: the server's (carried on here when it drops, if small enough), or one simulated here.
// Opened on a thread of its own while the window answers: a first connection may wait seconds
// for a server (5 s where none answers), and the window may be closed meanwhile, which stops it
// (a local fluid's start is waited for).
void Client::open() {
  HandoffOptions handoff;
  handoff.local = options_.local;
  handoff.handoff = options_.handoff;
  handoff.max_local_particles = options_.max_local_particles;
  handoff.say = [](const std::string& line) {
    std::fprintf(stderr, "fluidcast-client: %s\n", line.c_str());
  };
  handoff.stop = closing_.get_token();
  const v1::Hello hello = hello_for_window();
  auto opening = std::async(std::launch::async, [hello, handoff, this] {
    return std::make_unique<HandoffStream>(
        hello, handoff_sides(options_.server, options_.max_local_particles), handoff);
  });
  SDL_SetWindowTitle(window_.get(), options_.local
                                        ? "fluidcast — starting the fluid here"
                                        : ("fluidcast — connecting to " + options_.server).c_str());
  while (opening.wait_for(std::chrono::milliseconds(16)) != std::future_status::ready) {
    SDL_Event event;
    while (SDL_PollEvent(&event)) quit_ = quit_ || asks_to_quit(event);
    if (Clock::now() > end_) quit_ = true;
    if (quit_) closing_.request_stop();
    draw();
  }
  stream_ = opening.get();
  if (!stream_->welcome().session_id().empty()) {
    std::fprintf(stderr, "fluidcast-client: %s\n", describe_welcome(stream_->welcome()).c_str());
  }
  const v1::Viewport now = hello_for_window().viewport();
  if (now.width() != hello.viewport().width() || now.height() != hello.viewport().height()) {
    try {  // resized while it opened
      send_viewport();
    } catch (const std::exception& e) {
      complain(std::string("refused: ") + e.what());
    }
  }
}

void Client::send_viewport() {
  v1::Command command;
  *command.mutable_viewport() = hello_for_window().viewport();
  stream_->command(command);
}

Clock::duration Client::move_interval() const {
  const std::uint32_t rate =
      stream_ ? stream_->welcome().limits().max_input_events_per_second() : 0;
  if (rate == 0) return kMoveInterval;  // none said: the fluid here has no limit
  const double pointers = double(fingers_.size() + 1);
  return std::max<Clock::duration>(
      kMoveInterval, std::chrono::duration_cast<Clock::duration>(
                         std::chrono::duration<double>(2.0 * pointers / double(rate))));
}

void Client::pointer(std::uint32_t id, v1::PointerEvent::Phase phase, float window_x,
                     float window_y) {
  if (!stream_ || frame_width_ == 0) return;
  const auto now = Clock::now();
  if (phase == v1::PointerEvent::MOVE) {
    if (now - last_move_[id] < move_interval()) return;
    last_move_[id] = now;
  }
  int width = 0, height = 0;
  SDL_GetWindowSize(window_.get(), &width, &height);
  // The frame is letterboxed in the window: positions are normalised to the frame.
  const float scale = std::min(float(width) / frame_width_, float(height) / frame_height_);
  const float w = frame_width_ * scale, h = frame_height_ * scale;
  const float x = std::clamp((window_x - (width - w) / 2) / w, 0.0f, 1.0f);
  const float y = std::clamp((window_y - (height - h) / 2) / h, 0.0f, 1.0f);
  stream_->pointer(id, phase, x, y);
}

void Client::handle(const SDL_Event& event) {
  if (asks_to_quit(event)) {
    quit_ = true;
    return;
  }
  switch (event.type) {
    case SDL_MOUSEBUTTONDOWN:
    case SDL_MOUSEBUTTONUP:  // touches also arrive as fingers: their mouse copies are skipped
      // The left button drags; the others' clicks would press and lift the same pointer.
      if (event.button.which != SDL_TOUCH_MOUSEID && event.button.button == SDL_BUTTON_LEFT) {
        pointer(mouse_pointer(),
                event.type == SDL_MOUSEBUTTONDOWN ? v1::PointerEvent::DOWN : v1::PointerEvent::UP,
                float(event.button.x), float(event.button.y));
      }
      break;
    case SDL_MOUSEMOTION:
      if (event.motion.which != SDL_TOUCH_MOUSEID && (event.motion.state & SDL_BUTTON_LMASK)) {
        pointer(mouse_pointer(), v1::PointerEvent::MOVE, float(event.motion.x),
                float(event.motion.y));
      }
      break;
    case SDL_FINGERDOWN:
    case SDL_FINGERMOTION:
    case SDL_FINGERUP:
      handle_finger(event.tfinger, event.type);
      break;
    case SDL_SENSORUPDATE: {
      const auto now = Clock::now();
      if (!controls() || now - last_tilt_ < std::chrono::milliseconds(50)) break;
      last_tilt_ = now;
      // The accelerometer reads the reaction to gravity: gravity is its opposite.
      const float* a = event.sensor.data;
      const float magnitude = std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
      const v1::Range& range = stream_->welcome().rules().tilt_gravity();
      if (!(magnitude >= range.min() && magnitude <= range.max()))
        break;  // free fall, a first zero
      stream_->tilt(-a[0], -a[1], -a[2]);
      break;
    }
    case SDL_KEYDOWN:
      handle_key(event.key.keysym.sym);
      break;
    case SDL_WINDOWEVENT:
      if (event.window.event == SDL_WINDOWEVENT_SIZE_CHANGED && stream_) send_viewport();
      break;
    default:
      break;
  }
}

void Client::handle_finger(const SDL_TouchFingerEvent& finger, Uint32 type) {
  int width = 0, height = 0;
  SDL_GetWindowSize(window_.get(), &width, &height);
  auto found = fingers_.find(finger.fingerId);
  if (found == fingers_.end()) {
    if (type != SDL_FINGERDOWN || fingers_.size() >= mouse_pointer()) return;
    std::uint32_t id = 0;  // the smallest free
    while (std::any_of(fingers_.begin(), fingers_.end(),
                       [id](const auto& entry) { return entry.second == id; })) {
      ++id;
    }
    found = fingers_.emplace(finger.fingerId, id).first;
  }
  const auto phase = type == SDL_FINGERDOWN ? v1::PointerEvent::DOWN
                     : type == SDL_FINGERUP ? v1::PointerEvent::UP
                                            : v1::PointerEvent::MOVE;
  pointer(found->second, phase, finger.x * width, finger.y * height);
  if (type == SDL_FINGERUP) fingers_.erase(found);
}

// The server's scenes on keys 1 to 9, its device's renderers in turn (Welcome.rules).
void Client::handle_key(SDL_Keycode key) {
  if (!stream_) return;
  v1::Command command;
  const v1::InputRules& rules = stream_->welcome().rules();
  if (key == SDLK_r && controls()) {
    command.set_reset(true);
  } else if (key >= SDLK_1 && key <= SDLK_9 && key - SDLK_1 < rules.scenes_size() && controls()) {
    command.set_scene(rules.scenes(key - SDLK_1));
  } else if (key == SDLK_m && rules.renderers_size() > 0) {
    renderer_choice_ = (renderer_choice_ + 1) % rules.renderers_size();
    *command.mutable_quality() = options_.hello.quality();
    command.mutable_quality()->set_renderer(rules.renderers(renderer_choice_));
  } else if (key == SDLK_p && controls()) {
    command.set_pause(!stream_->welcome().state().paused());
  } else if (key == SDLK_F12) {
    screenshot_wanted_ = !options_.screenshot.empty();
  } else if (key == SDLK_h) {
    overlay_->toggle();
  }
  if (command.kind_case() != v1::Command::KIND_NOT_SET) stream_->command(command);
}

void Client::show(const v1::Frame& frame) {
  const codec::ImageRgba image = codec::decode_jpeg(
      {reinterpret_cast<const std::uint8_t*>(frame.jpeg().data()), frame.jpeg().size()});
  if (!texture_ || image.width != frame_width_ || image.height != frame_height_) {
    texture_.reset(SDL_CreateTexture(renderer_.get(), SDL_PIXELFORMAT_ABGR8888,
                                     SDL_TEXTUREACCESS_STREAMING, image.width, image.height));
    if (!texture_) throw std::runtime_error(std::string("SDL texture: ") + SDL_GetError());
    frame_width_ = image.width;
    frame_height_ = image.height;
  }
  SDL_UpdateTexture(texture_.get(), nullptr, image.pixels.data(), image.width * 4);
  ++frames_;
  recent_frames_.emplace_back(Clock::now(), frame.jpeg().size());
  last_frame_ = frame;
  last_frame_.clear_jpeg();
}

void Client::draw() {
  SDL_SetRenderDrawColor(renderer_.get(), 17, 17, 17, 255);
  SDL_RenderClear(renderer_.get());
  if (texture_) {
    int width = 0, height = 0;
    SDL_GetRendererOutputSize(renderer_.get(), &width, &height);
    const float scale = std::min(float(width) / frame_width_, float(height) / frame_height_);
    const SDL_Rect rect{int((width - frame_width_ * scale) / 2),
                        int((height - frame_height_ * scale) / 2), int(frame_width_ * scale),
                        int(frame_height_ * scale)};
    SDL_RenderCopy(renderer_.get(), texture_.get(), nullptr, &rect);
  }
  overlay_->draw();
  if (screenshot_wanted_) {
    screenshot_wanted_ = false;
    write_screenshot();
  }
  SDL_RenderPresent(renderer_.get());
}

void Client::update_title(Clock::time_point now) {
  if (now - last_title_ < std::chrono::milliseconds(500)) return;
  last_title_ = now;
  std::erase_if(recent_frames_,
                [&](const auto& frame) { return now - frame.first > std::chrono::seconds(2); });
  std::size_t bytes = 0;
  for (const auto& frame : recent_frames_) bytes += frame.second;
  const double fps = recent_frames_.size() / 2.0, kbps = 8.0 * bytes / 2.0 / 1000.0;
  const auto latencies = stream_ ? stream_->latencies_ms() : std::vector<double>{};
  char line[256];
  std::vector<std::string> lines;
  std::snprintf(line, sizeof line, "%.1f fps  %.0f kbit/s", fps, kbps);
  lines.emplace_back(line);
  std::snprintf(line, sizeof line, "touch→photon p50 %.0f ms, p95 %.0f ms",
                percentile(latencies, 0.5), percentile(latencies, 0.95));
  lines.emplace_back(line);
  const v1::StageTimings& t = last_frame_.timings();
  // The session as it is now, whoever changed it (ServerMessage.session).
  const v1::SessionState& session = stream_ ? stream_->welcome().state() : v1::SessionState();
  std::snprintf(line, sizeof line, "%s, %s, %u particles%s", session.scene().c_str(),
                session.solver().c_str(), session.particles(),
                session.paused() ? ", paused (p goes on)" : "");
  lines.emplace_back(line);
  std::snprintf(line, sizeof line, "%u×%u %s q%u  t=%.2f s  %.2f× real time%s", last_frame_.width(),
                last_frame_.height(), last_frame_.renderer().c_str(), last_frame_.jpeg_quality(),
                last_frame_.sim_time(), last_frame_.sim_speed(),
                !session.paused() && last_frame_.sim_speed() < 0.95f ? " (slow motion)" : "");
  lines.emplace_back(line);
  std::snprintf(line, sizeof line,
                "%s: sim %.1f queue %.1f render %.1f read-back %.2f encode %.1f ms",
                stream_ && stream_->simulating_here() ? "here" : "server", t.sim_ms(), t.queue_ms(),
                t.render_ms(), t.readback_ms(), t.encode_ms());
  lines.emplace_back(line);
  const auto gap = stream_ ? stream_->handoff_gap_ms() : std::nullopt;
  lines.push_back(status() +
                  (gap ? "; handoff gap " + std::to_string(int(*gap)) + " ms" : std::string()));
  overlay_->set_lines(lines);
  std::snprintf(line, sizeof line, "fluidcast — %s — %.1f fps, touch→photon p50 %.0f ms",
                status().c_str(), fps, percentile(latencies, 0.5));
  SDL_SetWindowTitle(window_.get(), line);
}

void Client::write_screenshot() const {
  int width = 0, height = 0;
  SDL_GetRendererOutputSize(renderer_.get(), &width, &height);
  codec::ImageRgba image(width, height);
  if (SDL_RenderReadPixels(renderer_.get(), nullptr, SDL_PIXELFORMAT_ABGR8888, image.pixels.data(),
                           width * 4) != 0) {
    std::fprintf(stderr, "fluidcast-client: screenshot: %s\n", SDL_GetError());
    return;
  }
  codec::write_png(options_.screenshot, image);
}

void Client::complain(std::string trouble) {
  trouble_ = std::move(trouble);
  trouble_until_ = Clock::now() + std::chrono::seconds(5);
}

std::string Client::status() const {
  const std::string said = stream_ ? stream_->status() : std::string();
  return Clock::now() < trouble_until_ ? said + "; " + trouble_ : said;
}

int Client::run() {
  window_.reset(SDL_CreateWindow("fluidcast", SDL_WINDOWPOS_UNDEFINED, SDL_WINDOWPOS_UNDEFINED,
                                 options_.width, options_.height,
                                 SDL_WINDOW_RESIZABLE | SDL_WINDOW_ALLOW_HIGHDPI));
  if (!window_) throw std::runtime_error(std::string("SDL window: ") + SDL_GetError());
  renderer_.reset(SDL_CreateRenderer(window_.get(), -1, 0));
  if (!renderer_) throw std::runtime_error(std::string("SDL renderer: ") + SDL_GetError());
  overlay_ = std::make_unique<StatsOverlay>(renderer_.get());
  for (int k = 0; k < SDL_NumSensors(); ++k) {
    if (SDL_SensorGetDeviceType(k) == SDL_SENSOR_ACCEL) {
      accelerometer_.reset(SDL_SensorOpen(k));
      break;
    }
  }
  if (options_.seconds > 0) {
    end_ = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                              std::chrono::duration<double>(options_.seconds));
  }
  try {
    open();
  } catch (const std::exception& e) {
    const auto* stopped = dynamic_cast<const StreamError*>(&e);
    if (stopped && stopped->code() == grpc::StatusCode::CANCELLED && closing_.stop_requested()) {
      std::printf("fluidcast-client: closed while connecting\n");
      return 0;
    }
    const bool unreachable = dynamic_cast<const Unreachable*>(&e) != nullptr;
    const std::string why = options_.local ? std::string("cannot start: ") + e.what()
                            : unreachable  ? std::string("cannot connect: ") + e.what()
                                           : "the server refused: " + options_.with_flags(e.what());
    std::fprintf(stderr, "fluidcast-client: %s\n", why.c_str());
    say_until_closed(why);
    return 1;
  }
  while (!quit_) {
    SDL_Event event;
    while (SDL_PollEvent(&event)) {
      try {
        handle(event);
      } catch (const std::exception& e) {  // input the session refused: say so, go on
        complain(std::string("refused: ") + e.what());
      }
    }
    const auto now = Clock::now();
    if (now > end_) break;
    if (const auto frame = stream_->next_frame(std::chrono::milliseconds(5))) {
      try {
        show(*frame);
      } catch (const std::exception& e) {
        complain(std::string("a frame could not be shown: ") + e.what());
      }
    }
    draw();
    update_title(now);
  }
  screenshot_wanted_ = !options_.screenshot.empty();
  draw();
  // A goodbye, not a drop: the server ends a session at once when its last viewer leaves, while
  // a dropped viewer's seat and session wait out --resume-grace, counted against this address.
  // The window goes first: a server that does not answer holds the goodbye up to seconds.
  SDL_HideWindow(window_.get());
  // Closed while a server that went is asked again is no failure; a stream that ended is.
  const bool ended = stream_->ended();
  const std::string ended_because = stream_->close();
  std::printf("fluidcast-client: %zu frames, %s\n", frames_, status().c_str());
  if (ended) {
    std::fprintf(stderr, "fluidcast-client: the stream ended: %s\n", ended_because.c_str());
    return 1;
  }
  return 0;
}

void Client::say_until_closed(const std::string& why) {
  SDL_SetWindowTitle(window_.get(), ("fluidcast — " + why).c_str());
  overlay_->set_lines({why, "Close the window (or press Esc) to quit."});
  while (!quit_ && Clock::now() < end_) {
    SDL_Event event;
    while (SDL_PollEvent(&event)) {
      quit_ = quit_ || asks_to_quit(event);
      if (event.type == SDL_WINDOWEVENT && event.window.event == SDL_WINDOWEVENT_SIZE_CHANGED) {
        overlay_->set_lines({why, "Close the window (or press Esc) to quit."});
      }
    }
    draw();
    SDL_Delay(16);
  }
  screenshot_wanted_ = !options_.screenshot.empty();
  draw();
}

}  // namespace

int run_window(const WindowOptions& options) {
  try {
    Client client(options);
    return client.run();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fluidcast-client: %s\n", e.what());
    return 2;
  }
}

}  // namespace fluidcast::client

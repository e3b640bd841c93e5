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
#include <mutex>

#include "fluidcast/codec/jpeg.h"
#include "fluidcast/codec/png.h"
#include "local_stream.h"
#include "stats_overlay.h"
#include "stream_client.h"

namespace fluidcast::client {
namespace {

using Clock = std::chrono::steady_clock;
// How far back in time a handoff may go: the fluid continues from the newest snapshot.
constexpr auto kSnapshotEvery = std::chrono::milliseconds(250);
constexpr auto kRetryEvery = std::chrono::seconds(2);
// A stream that sends nothing for this long is treated as lost (a wedged server, a dead route).
constexpr auto kStallAfter = std::chrono::seconds(5);
// Pointer moves sent per finger at most: the server limits input events per second.
constexpr auto kMoveInterval = std::chrono::milliseconds(16);
// Frames asked for are at most this many pixels along each side (aspect kept).
constexpr int kMaxViewportWidth = 1920, kMaxViewportHeight = 1080;

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

double percentile(std::vector<double> values, double p) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  return values[std::min(values.size() - 1, std::size_t(p * double(values.size())))];
}

// What the window shows, and where it comes from.
class Client {
 public:
  explicit Client(const WindowOptions& options) : options_(options) {}

  int run();

 private:
  void open_first();
  void handle(const SDL_Event& event);
  void pointer(std::uint32_t id, v1::PointerEvent::Phase phase, float window_x, float window_y);
  // The mouse takes the last pointer id the server allows (Welcome.rules), fingers those below.
  // Whether this viewer may change the fluid (it joined with a view key: no).
  bool controls() const { return stream_ && stream_->welcome().access().control(); }
  std::uint32_t mouse_pointer() const {
    return stream_ ? std::max(1u, stream_->welcome().rules().pointer_ids()) - 1 : 0;
  }
  void show(const v1::Frame& frame);
  void draw();
  void keep_snapshot();
  void keep_standby();
  void on_remote_lost();
  void try_reconnect();
  void update_title(Clock::time_point now);
  void screenshot() const;
  v1::Hello hello_for_window() const;

  WindowOptions options_;
  SdlLibrary sdl_;  // first in, last out: SDL_Quit after every SDL object is gone
  Window window_;
  Renderer renderer_;
  Texture texture_;
  int frame_width_ = 0, frame_height_ = 0;
  std::unique_ptr<StatsOverlay> overlay_;
  v1::Frame last_frame_;  // without its JPEG: what the overlay reports
  Sensor accelerometer_;

  std::unique_ptr<FluidStream> stream_;
  bool remote_ = false;
  std::string status_;  // what the title says besides the figures
  std::future<v1::Snapshot> snapshot_request_;
  std::vector<std::future<v1::Snapshot>> abandoned_;  // finished (or waited for) at exit
  std::optional<v1::Snapshot> snapshot_;
  Clock::time_point last_snapshot_{}, last_retry_{}, last_remote_frame_{}, last_title_{};
  // A new stream to the server, with the local fluid's state put into it on the same thread (a
  // slow server never stalls the window).
  struct Reconnected {
    std::unique_ptr<StreamClient> stream;
    std::optional<v1::Snapshot> state_put;  // what went in, if the fluid here did
    std::string put_error;                  // else why not, when it should have
  };
  std::future<Reconnected> reconnect_;
  // A local session kept warm while streaming (paused, one frame a second), so that a handoff
  // needs no start-up: Vulkan context, pipelines and solver are ready. Each snapshot goes into it
  // as it arrives, off this thread, so that on a drop it only has to resume.
  struct Standby {
    std::mutex mutex;  // held while a snapshot goes in, and while the standby is taken
    std::unique_ptr<LocalStream> local;  // null until started, and once taken
    bool holds_state = false;            // the newest snapshot went in
  };
  std::shared_ptr<Standby> standby_;
  std::future<void> standby_start_;
  // Frames reflecting events older than this show a state from before a handoff (the standby's,
  // or a new server session's before our state went in): not shown.
  std::uint64_t show_from_event_ = 0;
  bool report_next_frame_ = false;  // say the first frame's time after handing back
  std::optional<double> handoff_gap_ms_;
  bool awaiting_first_local_frame_ = false;
  std::map<SDL_FingerID, std::uint32_t> fingers_;
  std::map<std::uint32_t, Clock::time_point> last_move_;
  Clock::time_point last_tilt_{};
  std::size_t frames_ = 0;
  std::vector<std::pair<Clock::time_point, std::size_t>> recent_frames_;  // arrival, JPEG bytes
  bool quit_ = false;
  int renderer_choice_ = 0;
  bool paused_ = false;
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

void Client::open_first() {
  if (options_.local) {
    stream_ = std::make_unique<LocalStream>(hello_for_window(), options_.max_local_particles);
    status_ = "local";
    return;
  }
  stream_ = std::make_unique<StreamClient>(connect(options_.server), hello_for_window());
  remote_ = true;
  last_remote_frame_ = Clock::now();
  status_ = "streaming from " + options_.server;
  std::fprintf(stderr, "fluidcast-client: %s\n", describe_welcome(stream_->welcome()).c_str());
}

void Client::pointer(std::uint32_t id, v1::PointerEvent::Phase phase, float window_x,
                     float window_y) {
  if (!stream_ || frame_width_ == 0) return;
  const auto now = Clock::now();
  if (phase == v1::PointerEvent::MOVE) {
    if (now - last_move_[id] < kMoveInterval) return;
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
  switch (event.type) {
    case SDL_QUIT:
      quit_ = true;
      break;
    case SDL_MOUSEBUTTONDOWN:
    case SDL_MOUSEBUTTONUP:  // touches also arrive as fingers: their mouse copies are skipped
      if (event.button.which != SDL_TOUCH_MOUSEID) {
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
    case SDL_FINGERUP: {
      int width = 0, height = 0;
      SDL_GetWindowSize(window_.get(), &width, &height);
      auto found = fingers_.find(event.tfinger.fingerId);
      if (found == fingers_.end()) {
        if (event.type != SDL_FINGERDOWN || fingers_.size() >= mouse_pointer()) break;
        std::uint32_t id = 0;  // the smallest free
        while (std::any_of(fingers_.begin(), fingers_.end(),
                           [id](const auto& entry) { return entry.second == id; })) {
          ++id;
        }
        found = fingers_.emplace(event.tfinger.fingerId, id).first;
      }
      const auto phase = event.type == SDL_FINGERDOWN ? v1::PointerEvent::DOWN
                         : event.type == SDL_FINGERUP ? v1::PointerEvent::UP
                                                      : v1::PointerEvent::MOVE;
      pointer(found->second, phase, event.tfinger.x * width, event.tfinger.y * height);
      if (event.type == SDL_FINGERUP) fingers_.erase(found);
      break;
    }
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
    case SDL_KEYDOWN: {
      if (!stream_) break;
      v1::Command command;
      const SDL_Keycode key = event.key.keysym.sym;
      // The server's scenes on keys 1 to 9, its device's renderers in turn (Welcome.rules).
      const v1::InputRules& rules = stream_->welcome().rules();
      if (key == SDLK_ESCAPE || key == SDLK_q) {
        quit_ = true;
      } else if (key == SDLK_r && controls()) {
        command.set_reset(true);
      } else if (key >= SDLK_1 && key <= SDLK_9 && key - SDLK_1 < rules.scenes_size() &&
                 controls()) {
        command.set_scene(rules.scenes(key - SDLK_1));
      } else if (key == SDLK_m && rules.renderers_size() > 0) {
        renderer_choice_ = (renderer_choice_ + 1) % rules.renderers_size();
        *command.mutable_quality() = options_.hello.quality();
        command.mutable_quality()->set_renderer(rules.renderers(renderer_choice_));
      } else if (key == SDLK_p && controls()) {
        paused_ = !paused_;
        command.set_pause(paused_);
      } else if (key == SDLK_F12) {
        screenshot();
      } else if (key == SDLK_h) {
        overlay_->toggle();
      }
      if (command.kind_case() != v1::Command::KIND_NOT_SET) stream_->command(command);
      break;
    }
    case SDL_WINDOWEVENT:
      if (event.window.event == SDL_WINDOWEVENT_SIZE_CHANGED && stream_) {
        v1::Command command;
        *command.mutable_viewport() = hello_for_window().viewport();
        stream_->command(command);
      }
      break;
    default:
      break;
  }
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
  SDL_RenderPresent(renderer_.get());
}

// While streaming a session small enough to simulate here, keep its state, fetched on the side.
void Client::keep_snapshot() {
  std::erase_if(abandoned_, [](const std::future<v1::Snapshot>& request) {
    return request.wait_for(std::chrono::seconds(0)) == std::future_status::ready;
  });
  // A watcher does not continue the fluid: handed back, it would be a copy of someone's session.
  if (!remote_ || !options_.handoff || !controls()) return;
  if (snapshot_request_.valid() &&
      snapshot_request_.wait_for(std::chrono::seconds(0)) == std::future_status::ready) {
    try {
      snapshot_ = snapshot_request_.get();
    } catch (const std::exception&) {  // the server may be going: keep the one we have
    }
  }
  const auto now = Clock::now();
  if (snapshot_request_.valid() || now - last_snapshot_ < kSnapshotEvery) return;
  if (stream_->welcome().state().particles() > options_.max_local_particles) return;
  last_snapshot_ = now;
  auto* remote = static_cast<StreamClient*>(stream_.get());
  snapshot_request_ = std::async(
      std::launch::async, [channel = remote->channel(), key = remote->welcome().access().view_key(),
                           token = options_.hello.token(), standby = standby_] {
        v1::Snapshot snapshot = get_snapshot(channel, key, token);
        if (standby) {
          const std::lock_guard lock(standby->mutex);
          standby->holds_state = false;
          if (standby->local) {
            try {
              standby->local->load(snapshot);
              standby->holds_state = true;
            } catch (const std::exception&) {  // said when a handoff loads it again
            }
          }
        }
        return snapshot;
      });
}

void Client::keep_standby() {
  if (!remote_ || !options_.handoff || standby_ || !controls()) return;
  const v1::SessionState state = stream_->welcome().state();
  if (state.particles() > options_.max_local_particles) return;
  v1::Hello hello = hello_for_window();
  hello.mutable_create()->set_scene(state.scene());
  hello.mutable_create()->set_solver(state.solver());
  hello.mutable_create()->set_particles(state.particles());
  hello.mutable_quality()->set_renderer("mc");
  hello.mutable_quality()->set_max_fps(1);
  standby_ = std::make_shared<Standby>();
  standby_start_ = std::async(std::launch::async,
                              [standby = standby_, hello, cap = options_.max_local_particles] {
                                auto local = std::make_unique<LocalStream>(hello, cap);
                                v1::Command pause;
                                pause.set_pause(true);
                                local->command(pause);
                                const std::lock_guard lock(standby->mutex);
                                standby->local = std::move(local);
                              });
}

void Client::on_remote_lost() {
  const std::string why = stream_->end_reason();
  // A request still on its way to a dying server is not waited for: the last state will do.
  if (snapshot_request_.valid()) abandoned_.push_back(std::move(snapshot_request_));
  const v1::SessionState state = stream_->welcome().state();
  stream_.reset();
  remote_ = false;
  // A state the standby took on the side counts even before this thread collected it.
  const bool standby_has_state = standby_ && [this] {
    const std::lock_guard lock(standby_->mutex);
    return standby_->holds_state;
  }();
  if (!options_.handoff || !(snapshot_ || standby_has_state) ||
      state.particles() > options_.max_local_particles) {
    status_ = "the server is gone (" + why + "); " +
              (state.particles() > options_.max_local_particles
                   ? "this session is too big to continue here (" +
                         std::to_string(state.particles()) + " particles); "
                   : std::string()) +
              "retrying";
    std::fprintf(stderr, "fluidcast-client: %s\n", status_.c_str());
    return;
  }
  std::unique_ptr<LocalStream> local;
  bool holds_state = false;
  try {
    standby_start_.get();  // waits if it is still starting; says why it could not
    const std::lock_guard lock(standby_->mutex);  // and for a snapshot going in
    local = std::move(standby_->local);
    holds_state = standby_->holds_state;
  } catch (const std::exception& e) {
    standby_.reset();
    status_ = std::string("the server is gone and the local fluid cannot start: ") + e.what();
    std::fprintf(stderr, "fluidcast-client: %s\n", status_.c_str());
    return;
  }
  standby_.reset();
  try {
    if (!holds_state) local->load(snapshot_.value());  // throws if there is none after all
  } catch (const std::exception& e) {
    status_ = std::string("the server is gone and its state does not fit here: ") + e.what();
    std::fprintf(stderr, "fluidcast-client: %s\n", status_.c_str());
    return;
  }
  v1::Command wake;
  *wake.mutable_quality() = options_.hello.quality();
  if (wake.quality().renderer().empty()) wake.mutable_quality()->set_renderer("mc");
  local->command(wake);
  wake.set_pause(false);
  show_from_event_ = local->command(wake);
  stream_ = std::move(local);
  awaiting_first_local_frame_ = true;
  status_ = "the server is gone (" + why + "): continuing locally, retrying";
  std::fprintf(stderr, "fluidcast-client: %s\n", status_.c_str());
}

// In local mode after a drop, or with no stream at all: try the server again, on the side.
void Client::try_reconnect() {
  const auto now = Clock::now();
  if (reconnect_.valid()) {
    if (reconnect_.wait_for(std::chrono::seconds(0)) != std::future_status::ready) return;
    Reconnected reconnected;
    try {
      reconnected = reconnect_.get();
    } catch (const std::exception&) {
      return;  // still gone
    }
    std::unique_ptr<StreamClient> back = std::move(reconnected.stream);
    show_from_event_ = 0;
    if (const auto& state = reconnected.state_put) {
      std::fprintf(stderr,
                   "fluidcast-client: the server is back and took the state (%d particles, "
                   "t = %.3f s)\n",
                   state->positions_size() / 3, state->time());
      try {
        v1::Command marker;  // frames from before the state went in reflect no later event
        *marker.mutable_quality() = options_.hello.quality();
        show_from_event_ = back->command(marker);
        report_next_frame_ = true;
      } catch (const std::exception& e) {
        std::fprintf(stderr, "fluidcast-client: %s\n", e.what());
      }
    } else if (!reconnected.put_error.empty()) {
      std::fprintf(stderr, "fluidcast-client: the server is back but took no state: %s\n",
                   reconnected.put_error.c_str());
    }
    stream_ = std::move(back);
    remote_ = true;
    last_remote_frame_ = Clock::now();
    snapshot_.reset();
    status_ = "streaming from " + options_.server + " again";
    std::fprintf(stderr, "fluidcast-client: %s\n", status_.c_str());
    return;
  }
  if (now - last_retry_ < kRetryEvery) return;
  last_retry_ = now;
  v1::Hello hello = hello_for_window();
  if (stream_) {  // continue the local fluid's scene on the server
    hello.mutable_create()->set_scene(stream_->welcome().state().scene());
    hello.mutable_create()->set_solver(stream_->welcome().state().solver());
    hello.mutable_create()->set_particles(stream_->welcome().state().particles());
  }
  // The local stream outlives the task: stream_ changes only once the task is done, and
  // reconnect_ is destroyed (waited for) before stream_.
  auto* local = dynamic_cast<LocalStream*>(stream_.get());
  reconnect_ = std::async(
      std::launch::async, [server = options_.server, hello, local, token = options_.hello.token()] {
        Reconnected reconnected{std::make_unique<StreamClient>(connect(server), hello), {}, {}};
        if (!local) return reconnected;
        // The fluid here stops while its state goes over, so that nothing done meanwhile is lost.
        v1::ClientMessage pause;
        pause.mutable_command()->set_pause(true);
        try {
          local->send(pause);
          v1::Snapshot state = local->snapshot();
          reconnected.stream->put_snapshot(token, state);
          reconnected.state_put = std::move(state);
        } catch (const std::exception& e) {
          reconnected.put_error = e.what();
          pause.mutable_command()->set_pause(false);
          local->send(pause);
        }
        return reconnected;
      });
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
  std::snprintf(line, sizeof line, "%u×%u %s q%u  t=%.2f s  %.2f× real time%s", last_frame_.width(),
                last_frame_.height(), last_frame_.renderer().c_str(), last_frame_.jpeg_quality(),
                last_frame_.sim_time(), last_frame_.sim_speed(),
                last_frame_.sim_speed() < 0.95f ? " (slow motion)" : "");
  lines.emplace_back(line);
  std::snprintf(line, sizeof line,
                "%s: sim %.1f queue %.1f render %.1f read-back %.2f encode %.1f ms",
                remote_ ? "server" : "here", t.sim_ms(), t.queue_ms(), t.render_ms(),
                t.readback_ms(), t.encode_ms());
  lines.emplace_back(line);
  lines.push_back(status_ + (handoff_gap_ms_
                                 ? "; handoff gap " + std::to_string(int(*handoff_gap_ms_)) + " ms"
                                 : std::string()));
  overlay_->set_lines(lines);
  std::snprintf(line, sizeof line, "fluidcast — %s — %.1f fps, touch→photon p50 %.0f ms",
                status_.c_str(), fps, percentile(latencies, 0.5));
  SDL_SetWindowTitle(window_.get(), line);
}

void Client::screenshot() const {
  if (options_.screenshot.empty()) return;
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
  try {
    open_first();
  } catch (const std::exception& e) {
    status_ = std::string(options_.local ? "cannot start: " : "cannot connect: ") + e.what();
    std::fprintf(stderr, "fluidcast-client: %s\n", status_.c_str());
    if (options_.local || !options_.handoff) {
      SDL_SetWindowTitle(window_.get(), ("fluidcast — " + status_).c_str());
      return 1;
    }
  }
  const auto start = Clock::now();
  while (!quit_) {
    SDL_Event event;
    while (SDL_PollEvent(&event)) {
      try {
        handle(event);
      } catch (const std::exception& e) {  // input the session refused: say so, go on
        status_ = std::string("refused: ") + e.what();
      }
    }
    const auto now = Clock::now();
    if (options_.seconds > 0 && now - start > std::chrono::duration<double>(options_.seconds)) {
      break;
    }
    if (stream_) {
      auto frame = stream_->next_frame(std::chrono::milliseconds(5));
      if (frame && frame->input_event_id() < show_from_event_) frame.reset();
      if (frame && report_next_frame_) {
        report_next_frame_ = false;
        std::fprintf(stderr,
                     "fluidcast-client: first frame streamed after the handoff: t = %.3f s\n",
                     frame->sim_time());
      }
      if (frame) {
        try {
          show(*frame);
        } catch (const std::exception& e) {
          status_ = std::string("a frame could not be shown: ") + e.what();
        }
        if (remote_) last_remote_frame_ = Clock::now();
        if (awaiting_first_local_frame_) {
          awaiting_first_local_frame_ = false;
          handoff_gap_ms_ =
              std::chrono::duration<double, std::milli>(Clock::now() - last_remote_frame_).count();
          std::fprintf(stderr, "fluidcast-client: handoff gap %.0f ms\n", *handoff_gap_ms_);
        }
      }
      keep_snapshot();
      keep_standby();
      if (remote_ && !stream_->ended() && Clock::now() - last_remote_frame_ > kStallAfter) {
        static_cast<StreamClient*>(stream_.get())->drop();  // silent too long: lost
      }
      if (remote_ && stream_->ended()) on_remote_lost();
    } else {
      SDL_Delay(5);
    }
    if (!options_.local && !remote_) try_reconnect();
    draw();
    update_title(now);
  }
  screenshot();
  if (reconnect_.valid()) reconnect_.wait();
  std::printf("fluidcast-client: %zu frames, %s\n", frames_, status_.c_str());
  return 0;
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

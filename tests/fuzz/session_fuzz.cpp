// Fuzz target: any bytes as a few clients' streams into a running server — Hellos that create,
// join and resume sessions (some handing back a state), then touches, tilts, commands,
// acknowledgements, state requests, departures and snapshots taken and put back — each through the
// StreamProtocol (as gRPC's streams use it), SessionHub and ViewerLink, while the hub's worker
// ticks in real time (simulating, drawing, encoding) on this machine's Vulkan device with the
// validation layer on. The first byte picks the hub whose sessions simulate on the CPU (as on
// lavapipe) or on the GPU (as on a GPU). What no client may do to the server, checked as the input
// runs and at its end (a broken promise throws fuzzing::Defect):
// - end a stream with INTERNAL (a session failed), open one INTERNAL, or cause a Vulkan validation
//   message;
// - leave a session whose snapshot the server then refuses to take back (what a client that went
//   on with the fluid by itself hands back: finite, inside the tank, within the speed limit, not
//   pressed past twice the rest density);
// - stop the server serving: at the end a new viewer gets its Welcome and a frame.
#include <google/protobuf/io/zero_copy_stream_impl_lite.h>
#include <google/protobuf/stubs/logging.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <future>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <utility>
#include <variant>
#include <vector>

#include "client_messages.h"
#include "fluidcast/gpu/context.h"
#include "fuzz_bytes.h"
#include "session/session_hub.h"
#include "session/stream_protocol.h"

using namespace fluidcast;
using namespace fluidcast::server;
using namespace fluidcast::fuzzing;

// Protobuf logs every invalid UTF-8 string it refuses: thousands of lines, none of them a finding.
static const bool kQuiet = (google::protobuf::SetLogHandler(nullptr), true);
// The hub logs every session opened and every refusal: thousands of lines, none a finding.
static const bool kLogsQuiet = (spdlog::set_level(spdlog::level::err), true);

// Under ASan (make fuzz) no leak check at exit: Mesa's lavapipe leaves 128 bytes that no
// suppression can name (as for the GPU tests, tests/CMakeLists.txt).
extern "C" const char* __asan_default_options() { return "detect_leaks=0"; }

namespace {

using namespace std::chrono_literals;

// Small frames and fluids, so that an input runs in a fraction of a second on lavapipe; a session
// takes few viewers and ends a second after its last one dropped, so that an input meets these
// limits and the resume grace's end. Sessions: the server's defaults (an input's address reaches
// its limit of 4; the new viewer at the end comes from another).
ServerLimits fuzz_limits() {
  ServerLimits limits;
  limits.max_particles = 1500;
  limits.default_particles = 300;
  limits.max_width = 160;
  limits.max_height = 120;
  limits.target_fps = 30;
  limits.max_viewers_per_session = 3;
  limits.resume_grace = 1s;
  return limits;
}

// What the server sends a viewer, as a transport's stream would take it.
class RecordingSink : public ViewerSink {
 public:
  bool deliver(std::shared_ptr<const v1::ServerMessage> message) override {
    std::lock_guard lock(mutex_);
    if (message->has_welcome()) welcome_ = message->welcome();
    if (message->has_frame()) {
      ++frames_;
      last_sequence_ = message->frame().sequence();
    }
    if (message->has_state()) state_ = message->state();
    changed_.notify_all();
    return true;
  }
  void end(const Refusal& why) override {
    std::lock_guard lock(mutex_);
    if (!ended_) ended_ = why;
    changed_.notify_all();
  }

  std::optional<v1::Welcome> welcome() const {
    std::lock_guard lock(mutex_);
    return welcome_;
  }
  std::optional<Refusal> ended() const {
    std::lock_guard lock(mutex_);
    return ended_;
  }
  // The last frame's sequence number (0 before the first), for an acknowledgement.
  std::uint64_t last_sequence() const {
    std::lock_guard lock(mutex_);
    return last_sequence_;
  }
  // The last answer to a StateRequest.
  std::optional<v1::Snapshot> state() const {
    std::lock_guard lock(mutex_);
    return state_;
  }
  // Waits up to `timeout` for a frame beyond those seen so far; false if none came.
  bool next_frame(std::chrono::milliseconds timeout) {
    std::unique_lock lock(mutex_);
    const std::uint64_t seen = frames_;
    return changed_.wait_for(lock, timeout, [&] { return frames_ > seen || ended_; }) &&
           frames_ > seen;
  }

 private:
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::optional<v1::Welcome> welcome_;
  std::uint64_t frames_ = 0;
  std::uint64_t last_sequence_ = 0;
  std::optional<v1::Snapshot> state_;
  std::optional<Refusal> ended_;
};

void expect_not_internal(const std::optional<Refusal>& refusal, const char* where) {
  if (refusal && refusal->code() == RefusalCode::internal)
    defect(std::string(where) + " ended INTERNAL: " + refusal->what());
}

// One Vulkan context with the validation layer for every input. The layer keeps some memory of
// every hub whose sessions simulated on the GPU: 4 MB each on a context kept, 10 MB with a
// context made anew each time (release build; none without the layer, and nothing reported left
// at the device's end).
gpu::Context& fuzz_context() {
  static gpu::Context context([] {
    gpu::ContextOptions options = gpu::options_from_environment();
    options.validation = true;
    return options;
  }());
  return context;
}

// A server of the input's own, stopped before the input ends: what an input does depends on it
// alone, and no worker is still drawing while the process exits (the validation layer's statics
// go before the context).
struct Server {
  explicit Server(bool gpu_solver)
      : validation_before(fuzz_context().validation_errors().size()),
        hub(fuzz_context(), gpu_solver, fuzz_limits(), std::nullopt, metrics) {}

  void expect_no_validation_messages() const {
    const auto messages = fuzz_context().validation_errors();
    if (messages.size() != validation_before)
      defect("a validation message: " + messages[validation_before]);
  }

  std::size_t validation_before;
  Metrics metrics;
  SessionHub hub;
};

// A stream as a transport runs it: its protocol, and once open the link to its viewer.
struct Stream {
  explicit Stream(SessionHub& hub) : protocol(hub.limits(), hub.token()), metrics(&hub.metrics()) {}
  std::shared_ptr<RecordingSink> sink = std::make_shared<RecordingSink>();
  StreamProtocol protocol;
  Metrics* metrics;
  std::shared_ptr<ViewerLink> link;
  bool ended = false;
};

std::variant<StreamProtocol::Open, StreamProtocol::Post> receive(Stream& stream,
                                                                 const v1::ClientMessage& message) {
  const std::string bytes = message.SerializeAsString();
  google::protobuf::io::ArrayInputStream input(bytes.data(), static_cast<int>(bytes.size()));
  return stream.protocol.receive(input);
}

// The stream ends as a transport ends one: the viewer leaves its session.
void end(Stream& stream, Departure departure) {
  stream.ended = true;
  if (stream.link) stream.link->leave(departure);
  stream.link.reset();
}

// Opens a stream with `message` (a Hello, or anything a client sends first) as a transport does,
// and waits for its first frame; false when it was refused or ended.
bool open(SessionHub& hub, Stream& stream, const v1::ClientMessage& message,
          const std::string& address, Known& known) {
  try {
    const auto first = receive(stream, message);
    const auto* opening = std::get_if<StreamProtocol::Open>(&first);
    if (!opening) defect("a stream's first message was taken as an event");
    std::promise<SessionHub::Opened> opened;
    hub.open(opening->hello, address, stream.sink,
             [&](SessionHub::Opened result) { opened.set_value(std::move(result)); });
    SessionHub::Opened result = opened.get_future().get();
    expect_not_internal(result.refusal, "opening a session");
    if (result.refusal) throw *result.refusal;
    stream.link = std::move(result.viewer);
    stream.protocol.opened(result.access);
  } catch (const Refusal& refusal) {
    record_refusal(*stream.metrics, Transport::grpc, refusal);
    end(stream, Departure::dropped);
    return false;
  }
  const bool framed = stream.sink->next_frame(20s);
  if (!framed && !stream.sink->ended()) defect("an open stream got no frame in 20 s");
  const auto welcome = stream.sink->welcome();
  if (!welcome) defect("an open stream got no Welcome");
  for (const std::string& key : {welcome->access().view_key(), welcome->access().control_key(),
                                 welcome->access().resume_key()})
    if (!key.empty()) known.keys.push_back(key);
  return framed;
}

void send(Stream& stream, const v1::ClientMessage& message) {
  if (stream.ended) return;
  try {
    const auto received = receive(stream, message);
    if (!std::holds_alternative<StreamProtocol::Post>(received))
      defect("an open stream's message was taken as a Hello");
    stream.link->post(std::get<StreamProtocol::Post>(received).message);
  } catch (const Refusal& refusal) {
    record_refusal(*stream.metrics, Transport::grpc, refusal);
    end(stream, Departure::dropped);
  }
}

// The session's snapshot for `key`; nothing for a key that opens no session. The hub answers on
// its worker: what it says is checked here.
std::optional<v1::Snapshot> snapshot_of(SessionHub& hub, const std::string& key) {
  std::promise<std::pair<std::optional<v1::Snapshot>, std::optional<Refusal>>> taken;
  hub.snapshot(key, [&](std::optional<v1::Snapshot> snapshot, std::optional<Refusal> refusal) {
    taken.set_value({std::move(snapshot), std::move(refusal)});
  });
  auto [snapshot, refusal] = taken.get_future().get();
  expect_not_internal(refusal, "a snapshot");
  return std::move(snapshot);
}

std::optional<Refusal> load(SessionHub& hub, const std::string& key, v1::Snapshot snapshot) {
  std::promise<std::optional<Refusal>> loaded;
  hub.load(key, std::make_shared<const v1::Snapshot>(std::move(snapshot)),
           [&](std::uint32_t, std::optional<Refusal> refusal) { loaded.set_value(refusal); });
  return loaded.get_future().get();
}

// The server refuses the session's own snapshot (key: a control key), taken now.
std::optional<Refusal> own_snapshot_refused(SessionHub& hub, const std::string& key) {
  std::optional<v1::Snapshot> snapshot = snapshot_of(hub, key);
  if (!snapshot) return std::nullopt;  // ended
  // Not promised (docs/protocol.md): a clock that went on from a time a client put near the
  // limit passes it.
  snapshot->set_time(std::min(snapshot->time(), kMaxSnapshotSeconds));
  return load(hub, key, *std::move(snapshot));
}

// Every session this input reached gives a snapshot the server takes back: finite, inside its
// tank, within the speed limit, nowhere pressed past twice the rest density (Session::load).
void expect_sessions_sound(SessionHub& hub, const Known& known) {
  for (const std::string& key : known.keys) {
    // A rebuild the input asked for may come between the snapshot and its load: the load then
    // rebuilds the session for the snapshot's scene, solver and count.
    const std::optional<Refusal> refusal = own_snapshot_refused(hub, key);
    expect_not_internal(refusal, "putting a session's own snapshot back");
    // A view key may not put it, and a resume key opens nothing; a session whose viewers all left
    // may have ended meanwhile.
    if (refusal && refusal->code() != RefusalCode::permission_denied &&
        refusal->code() != RefusalCode::not_found)
      defect(std::string("the server refused a session's own snapshot: ") + refusal->what());
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  Bytes in(data, size);
  Server chosen(in.byte() % 2);
  SessionHub& hub = chosen.hub;
  const ServerLimits& limits = hub.limits();
  const std::string address = "10.0.0.1";

  // Enough opens to fill a session's viewers and the address's sessions now and then.
  constexpr int kMostActions = 48;
  constexpr std::size_t kMostOpens = 10, kMostLive = 4;
  Known known;
  std::vector<std::unique_ptr<Stream>> streams;
  std::vector<Stream*> live;
  for (int action = 0; action < kMostActions && !in.done(); ++action) {
    std::erase_if(live, [](const Stream* stream) { return stream->ended; });
    const int kind = in.byte() % 12;
    if (kind == 0 || live.empty()) {
      if (streams.size() == kMostOpens || live.size() == kMostLive) continue;
      for (const auto& stream : streams)
        if (auto state = stream->sink->state()) known.state = std::move(state);
      streams.push_back(std::make_unique<Stream>(hub));
      live.push_back(streams.back().get());
      const v1::ClientMessage first =
          in.byte() % 16 == 15 ? event(in, limits, known, 0) : hello(in, limits, known);
      open(hub, *streams.back(), first, address, known);
    } else if (kind <= 6) {
      Stream& stream = *live[in.byte() % live.size()];
      send(stream, event(in, limits, known, stream.sink->last_sequence()));
    } else if (kind <= 8) {
      // Now and then past the resume grace: a dropped viewer's session ends.
      const int wait = in.byte();
      std::this_thread::sleep_for(std::chrono::milliseconds(wait < 250 ? wait % 50 : 1100));
    } else if (kind == 9) {
      Stream& stream = *live[in.byte() % live.size()];
      end(stream, in.byte() % 2 ? Departure::left : Departure::dropped);
    } else if (kind == 10) {
      if (auto snapshot = snapshot_of(hub, known.key(in))) known.state = std::move(snapshot);
    } else if (known.state) {
      const std::string key = known.key(in);
      expect_not_internal(load(hub, key, handed_back(in, *known.state)), "putting a snapshot");
    }
  }
  expect_sessions_sound(hub, known);
  for (const auto& stream : streams) end(*stream, Departure::left);

  Stream fresh(hub);
  Known unused;
  v1::ClientMessage message;
  message.mutable_hello()->mutable_viewport()->set_width(64);
  message.mutable_hello()->mutable_viewport()->set_height(48);
  if (!open(hub, fresh, message, "10.0.0.2", unused))
    defect("a new viewer got no frame after the input");
  end(fresh, Departure::left);
  for (const auto& stream : streams) expect_not_internal(stream->sink->ended(), "a stream");
  chosen.expect_no_validation_messages();
  return 0;
}

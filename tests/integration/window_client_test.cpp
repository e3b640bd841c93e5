// The native client with a window, under Xvfb: a streamed frame on screen, local mode on its own,
// the local cap, a refusal and an ended stream said, and the handoff (the server dies mid-stream,
// the client carries the fluid on, the server comes back and the client streams again); and the
// same handoff headless.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <regex>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "fluidcast/codec/png.h"
#include "server_process.h"

namespace fluidcast {
namespace {

struct ClientRun {
  int status = -1;
  std::string output;  // stdout and stderr together
};

// Runs the client (under a virtual display unless headless), collecting what it prints.
ClientRun run_client(const std::string& flags) {
  const std::string display = flags.find("--headless") == std::string::npos
                                  ? "xvfb-run -a -s '-screen 0 1280x800x24' "
                                  : "";
  const std::string command = display + FLUIDCAST_CLIENT_PATH + " " + flags + " 2>&1";
  ClientRun run;
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) return run;
  std::array<char, 4096> chunk;
  while (std::fgets(chunk.data(), chunk.size(), pipe)) run.output += chunk.data();
  const int status = pclose(pipe);
  run.status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return run;
}

// The client headless, as a process of its own that a test sends signals to (SIGINT as from a
// terminal, not ignored as a background job's is); what it prints is read as it comes.
class HeadlessClient {
 public:
  explicit HeadlessClient(std::vector<std::string> flags) {
    int out[2];
    if (pipe(out) != 0) throw std::runtime_error("pipe failed");
    flags.insert(flags.begin(), {FLUIDCAST_CLIENT_PATH, "--headless"});
    std::vector<char*> argv;  // before the fork: the child only execs
    for (auto& flag : flags) argv.push_back(flag.data());
    argv.push_back(nullptr);
    pid_ = fork();
    if (pid_ == 0) {
      std::signal(SIGINT, SIG_DFL);
      dup2(out[1], STDOUT_FILENO);
      dup2(out[1], STDERR_FILENO);
      close(out[0]);
      execv(argv[0], argv.data());
      _exit(127);
    }
    close(out[1]);
    output_ = fdopen(out[0], "r");
  }
  ~HeadlessClient() {
    if (pid_ > 0) finish();
  }
  // Reads what it prints until a line holds `text`; false when it ended first.
  bool wait_for(const std::string& text) {
    std::array<char, 4096> line;
    while (std::fgets(line.data(), line.size(), output_)) {
      run_.output += line.data();
      if (std::string_view(line.data()).find(text) != std::string_view::npos) return true;
    }
    return false;
  }
  void signal(int signal) const { kill(pid_, signal); }
  // Whether its main thread holds `signal` back now (a client that waits for it does), within 10 s.
  bool holds_back(int signal) const {
    for (int k = 0; k < 100; ++k) {
      std::ifstream status("/proc/" + std::to_string(pid_) + "/status");
      std::string line;
      while (std::getline(status, line)) {
        if (line.rfind("SigBlk:", 0) == 0 &&
            (std::stoull(line.substr(7), nullptr, 16) >> (signal - 1)) & 1) {
          return true;
        }
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    return false;
  }
  // What it printed, and how it ended, once it has.
  const ClientRun& finish() {
    wait_for("\n\n\n");  // everything: no line holds it
    std::fclose(output_);
    int status = 0;
    waitpid(pid_, &status, 0);
    pid_ = -1;
    run_.status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return run_;
  }

 private:
  pid_t pid_ = -1;
  FILE* output_ = nullptr;
  ClientRun run_;
};

// The last line that is a JSON object: the headless client's report with --json.
nlohmann::json report_in(const std::string& output) {
  const std::size_t line = output.rfind("\n{") + 1;
  return nlohmann::json::parse(output.substr(line, output.find('\n', line) - line));
}

// Whether the server has no session left within `within`: a client that said goodbye as its
// session's last viewer ended it; a dropped one's seat and session wait out --resume-grace (30 s).
bool sessions_end_within(const testing::ServerProcess& server, std::chrono::seconds within) {
  const auto until = std::chrono::steady_clock::now() + within;
  while (server.metric("fluidcast_sessions") != 0) {
    if (std::chrono::steady_clock::now() > until) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  return true;
}

// Standard deviation of brightness: a picture, not a blank window.
double spread(const codec::ImageRgba& image) {
  double sum = 0, squares = 0;
  const std::size_t pixels = std::size_t(image.width) * image.height;
  for (std::size_t k = 0; k < pixels; ++k) {
    const double v = image.pixels[4 * k] + image.pixels[4 * k + 1] + image.pixels[4 * k + 2];
    sum += v;
    squares += v * v;
  }
  const double mean = sum / pixels;
  return std::sqrt(std::max(0.0, squares / pixels - mean * mean));
}

int frames_in(const std::string& output) {
  std::smatch match;
  return std::regex_search(output, match, std::regex("fluidcast-client: ([0-9]+) frames"))
             ? std::stoi(match[1])
             : 0;
}

const std::string kOut = "test-output/";

// A loopback port no socket holds now, below the range the kernel hands out to outgoing
// connections (ip_local_port_range): a server's own port 0 comes from that range, and while the
// server was away another test's connection took it as its source port once, so the server could
// not come back on it.
int port_below_the_ephemeral_range() {
  int lowest_ephemeral = 32768;
  std::ifstream("/proc/sys/net/ipv4/ip_local_port_range") >> lowest_ephemeral;
  std::mt19937 random(std::random_device{}());
  std::uniform_int_distribution<int> pick(std::max(1024, lowest_ephemeral - 8000),
                                          lowest_ephemeral - 1);
  for (int attempt = 0; attempt < 100; ++attempt) {
    const int port = pick(random);
    const int probe = socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_port = htons(static_cast<std::uint16_t>(port));
    address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    const bool free = bind(probe, reinterpret_cast<const sockaddr*>(&address), sizeof address) == 0;
    close(probe);
    if (free) return port;
  }
  throw std::runtime_error("no free loopback port below the ephemeral range");
}

// A server that goes away `after` and comes back on the same port `for_how_long` later (SIGTERM:
// every stream ends with UNAVAILABLE).
class Outage {
 public:
  Outage(std::chrono::seconds after, std::chrono::seconds for_how_long)
      : server_(std::make_unique<testing::ServerProcess>(std::vector<std::string>{
            "--grpc-port", std::to_string(port_below_the_ephemeral_range())})),
        address_(server_->grpc_address()) {
    thread_ = std::thread([this, after, for_how_long] {
      std::this_thread::sleep_for(after);
      server_.reset();
      std::this_thread::sleep_for(for_how_long);
      try {
        server_ = std::make_unique<testing::ServerProcess>(
            std::vector<std::string>{"--grpc-port", address_.substr(address_.rfind(':') + 1)});
      } catch (const std::exception& e) {  // said by the test, not by std::terminate
        restart_failure_ = e.what();
      }
    });
  }
  ~Outage() {
    thread_.join();
    if (!restart_failure_.empty())
      ADD_FAILURE() << "the server did not come back: " << restart_failure_;
  }
  const std::string& address() const { return address_; }

 private:
  std::unique_ptr<testing::ServerProcess> server_;
  const std::string address_;
  std::string restart_failure_;
  std::thread thread_;
};

TEST(WindowClientTest, ShowsAStreamedFrame) {
  std::filesystem::create_directories(kOut);
  testing::ServerProcess server;
  const ClientRun run = run_client("--server " + server.grpc_address() +
                                   " --particles 1000 --width 320 --height 240 --seconds 5 "
                                   "--screenshot " +
                                   kOut + "window_streamed.png");
  std::printf("%s", run.output.c_str());
  ASSERT_EQ(run.status, 0);
  EXPECT_GT(frames_in(run.output), 5);
  const auto image = codec::read_png(kOut + "window_streamed.png");
  EXPECT_EQ(image.width, 320);
  EXPECT_GT(spread(image), 20.0);
  EXPECT_TRUE(sessions_end_within(server, std::chrono::seconds(5))) << "the window left no goodbye";
}

// AddressSanitizer slows the client, its local fluid and the server's restart several times.
// A gap this long means the handoff is broken (a retry loop's seconds, or no local frame at all):
// under ASan alone the gap measured 370–420 ms, and beside another handoff test on two cores
// 1039 ms once and 2044 ms once (the streamed frames then came at 2 a second); in the plain build
// 80 ms. Runs watch longer there: on CI's two cores, beside the other handoff test, the headless
// run's 6 s after the server came back once ended before the server had taken the state, and a
// local run drew 9 frames in 5 s beside another client test.
#if defined(__SANITIZE_ADDRESS__)
constexpr double kHandoffGapBoundMs = 3000.0;
constexpr int kLongerUnderAsanSeconds = 10;
#else
constexpr double kHandoffGapBoundMs = 1000.0;
constexpr int kLongerUnderAsanSeconds = 0;
#endif

// A window whose server does not answer yet still answers its user: it ends at its --seconds (or
// when closed) rather than after the first connection's 5 s, and says so.
TEST(WindowClientTest, AWindowWaitingForItsServerStillCloses) {
  const auto start = std::chrono::steady_clock::now();
  const ClientRun run = run_client(
      "--server 127.0.0.1:" + std::to_string(port_below_the_ephemeral_range()) + " --seconds 1");
  const auto took = std::chrono::steady_clock::now() - start;
  std::printf("%s", run.output.c_str());
  EXPECT_EQ(run.status, 0);
  EXPECT_NE(run.output.find("closed while connecting"), std::string::npos);
  EXPECT_LT(took, std::chrono::seconds(5 + kLongerUnderAsanSeconds / 5))
      << "the window waited for the connection (6.5 s)";
}

TEST(WindowClientTest, LocalModeSimulatesAndRendersWithoutAServer) {
  std::filesystem::create_directories(kOut);
  const ClientRun run = run_client("--local --particles 2000 --width 320 --height 240 --seconds " +
                                   std::to_string(5 + kLongerUnderAsanSeconds) + " --screenshot " +
                                   kOut + "window_local.png");
  std::printf("%s", run.output.c_str());
  ASSERT_EQ(run.status, 0);
  EXPECT_GT(frames_in(run.output), 10);
  EXPECT_GT(spread(codec::read_png(kOut + "window_local.png")), 20.0);
}

TEST(WindowClientTest, LocalModeRefusesMoreThanItsCap) {
  const ClientRun run = run_client("--local --particles 9000 --seconds 2");
  std::printf("%s", run.output.c_str());
  EXPECT_NE(run.status, 0);
  EXPECT_NE(run.output.find("at most 8000 particles"), std::string::npos);
}

TEST(WindowClientTest, AnAddressWithNoServerSaysSo) {
  // Longer than the 5 s a first connection waits: the run would end first.
  const ClientRun run = run_client("--server 127.0.0.1:1 --no-handoff --seconds 10");
  std::printf("%s", run.output.c_str());
  EXPECT_NE(run.status, 0);
  EXPECT_NE(run.output.find("cannot connect"), std::string::npos);
}

// A refusal at the start names the flag that set the refused field, for the person who typed it;
// a window says it until it is closed (here by --seconds) instead of vanishing at once.
TEST(WindowClientTest, ARefusalAtTheStartNamesItsFlagAndStaysInTheWindow) {
  std::filesystem::create_directories(kOut);
  const auto token_file = std::filesystem::temp_directory_path() / "fluidcast_window_token";
  std::ofstream(token_file) << "open sesame\n";
  testing::ServerProcess server({"--token-file", token_file.string()});
  const std::string shot = kOut + "window_refused.png";
  std::filesystem::remove(shot);
  const ClientRun window = run_client("--server " + server.grpc_address() +
                                      " --width 480 --height 200 --seconds 2 --screenshot " + shot);
  std::printf("%s", window.output.c_str());
  EXPECT_EQ(window.status, 1);
  EXPECT_NE(window.output.find("set Hello.token (--token)"), std::string::npos);
  ASSERT_TRUE(std::filesystem::exists(shot)) << "the window closed without showing why";
  EXPECT_GT(spread(codec::read_png(shot)), 20.0) << "no text in the window";

  const ClientRun headless = run_client("--headless --server " + server.grpc_address() +
                                        " --token 'open says me' --particles 500");
  std::printf("%s", headless.output.c_str());
  EXPECT_EQ(headless.status, 1);
  EXPECT_NE(headless.output.find("Hello.token (--token) is not"), std::string::npos);
}

// A window whose stream the server ended (an idle session) says why and exits with 1, as a
// headless run does.
TEST(WindowClientTest, AWindowWhoseStreamTheServerEndedSaysWhy) {
  testing::ServerProcess server({"--idle-timeout", "1"});
  const ClientRun run = run_client("--server " + server.grpc_address() +
                                   " --particles 500 --width 320 --height 240 --seconds " +
                                   std::to_string(4 + kLongerUnderAsanSeconds));
  std::printf("%s", run.output.c_str());
  EXPECT_EQ(run.status, 1);
  EXPECT_NE(run.output.find("the stream ended:"), std::string::npos);
  EXPECT_NE(run.output.find("--idle-timeout"), std::string::npos);
}

// The server dies mid-stream: the client continues the same fluid locally, keeps retrying, and
// streams again when the server is back on the same port, with its state put into the session.
TEST(WindowClientTest, HandsOffToLocalAndBack) {
  std::filesystem::create_directories(kOut);
  Outage outage(std::chrono::seconds(5), std::chrono::seconds(5));
  const ClientRun run = run_client("--server " + outage.address() +
                                   " --scene drop --particles 1500 --width 320 --height 240 "
                                   "--seconds " +
                                   std::to_string(20 + kLongerUnderAsanSeconds) + " --screenshot " +
                                   kOut + "window_handoff.png");
  std::printf("%s", run.output.c_str());
  ASSERT_EQ(run.status, 0);
  EXPECT_NE(run.output.find("continuing locally"), std::string::npos);
  std::smatch gap;
  ASSERT_TRUE(std::regex_search(run.output, gap, std::regex("handoff gap ([0-9]+) ms")));
  std::printf("handoff gap: %s ms\n", gap[1].str().c_str());
  // The server's new session goes on from the client's fluid, clock included: its first frame
  // is not earlier than the state put in (a fresh session would start at t = 0).
  std::smatch put, first;
  ASSERT_TRUE(std::regex_search(run.output, put,
                                std::regex("took the state \\([0-9]+ particles, t = ([0-9.]+) s")));
  ASSERT_TRUE(std::regex_search(
      run.output, first, std::regex("first frame streamed after the handoff: t = ([0-9.]+)")));
  EXPECT_GT(std::stod(put[1]), 0.05);
  EXPECT_GE(std::stod(first[1]), std::stod(put[1]));
  EXPECT_NE(run.output.find("again"), std::string::npos);
  EXPECT_GT(spread(codec::read_png(kOut + "window_handoff.png")), 20.0);
}

// The same handoff without a window: the figures say where the fluid was and how long the gap.
TEST(WindowClientTest, TheHeadlessClientHandsOffWhenAsked) {
  Outage outage(std::chrono::seconds(4), std::chrono::seconds(4));
  const ClientRun run = run_client("--headless --handoff --server " + outage.address() +
                                   " --particles 1500 --json --seconds " +
                                   std::to_string(14 + kLongerUnderAsanSeconds));
  std::printf("%s", run.output.c_str());
  ASSERT_EQ(run.status, 0);
  EXPECT_NE(run.output.find("continuing locally"), std::string::npos);
  EXPECT_NE(run.output.find("took the state"), std::string::npos);
  const nlohmann::json report = report_in(run.output);
  EXPECT_EQ(report["status"], "OK");
  EXPECT_FALSE(report["simulated_here"].get<bool>()) << "streaming again at the end";
  ASSERT_TRUE(report["handoff_gap_ms"].is_number());
  EXPECT_LT(report["handoff_gap_ms"].get<double>(), kHandoffGapBoundMs);
  EXPECT_EQ(report["bad_frames"], 0);
}

// Without --handoff a headless run measures one stream: it ends with it, and says why.
TEST(WindowClientTest, AHeadlessRunEndsWithItsServer) {
  Outage outage(std::chrono::seconds(3), std::chrono::seconds(0));
  const ClientRun run =
      run_client("--headless --server " + outage.address() + " --particles 500 --seconds 10");
  std::printf("%s", run.output.c_str());
  EXPECT_EQ(run.status, 1);
  EXPECT_NE(run.output.find("the stream ended: the server is gone"), std::string::npos);
}

// Ctrl-C ends a headless run early as its end would: the figures so far, and a goodbye (the
// server ends the session at once, where a killed client's waited out --resume-grace); the exit
// status is a run SIGINT ended.
TEST(WindowClientTest, CtrlCEndsAHeadlessRunWithItsFiguresAndAGoodbye) {
  testing::ServerProcess server;
  HeadlessClient client(
      {"--server", server.grpc_address(), "--particles", "500", "--seconds", "30", "--json"});
  ASSERT_TRUE(client.wait_for("you control it"));
  for (int k = 0; k < 100 && server.metric("fluidcast_frames_sent_total") < 5; ++k) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  client.signal(SIGINT);
  const ClientRun& run = client.finish();
  std::printf("%s", run.output.c_str());
  EXPECT_EQ(run.status, 128 + SIGINT);
  ASSERT_NE(run.output.find("\n{"), std::string::npos) << "no report";
  const nlohmann::json report = report_in(run.output);
  EXPECT_EQ(report["status"], "stopped by SIGINT");
  EXPECT_GT(report["frames"].get<int>(), 0);
  EXPECT_LT(report["seconds"].get<double>(), 20.0);
  EXPECT_TRUE(sessions_end_within(server, std::chrono::seconds(5))) << "no goodbye";
}

// Ctrl-C while the client waits for a server that is not there (up to 5 s) ends it at once.
TEST(WindowClientTest, CtrlCEndsAHeadlessRunWhileItConnects) {
  HeadlessClient client({"--server",
                         "127.0.0.1:" + std::to_string(port_below_the_ephemeral_range()),
                         "--seconds", "30"});
  ASSERT_TRUE(client.holds_back(SIGINT));
  std::this_thread::sleep_for(std::chrono::milliseconds(300));  // into the connection's wait
  const auto stopped = std::chrono::steady_clock::now();
  client.signal(SIGINT);
  const ClientRun& run = client.finish();
  std::printf("%s", run.output.c_str());
  EXPECT_EQ(run.status, 128 + SIGINT);
  EXPECT_NE(run.output.find("stopped by SIGINT while connecting"), std::string::npos);
  EXPECT_LT(std::chrono::steady_clock::now() - stopped, std::chrono::seconds(2));
}

}  // namespace
}  // namespace fluidcast

// The real fluidcast-server as a child process on an ephemeral loopback port: started with the
// given flags, its gRPC and HTTP ports read from its first lines, stopped with SIGTERM.
#pragma once

#include <arpa/inet.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "raw_connection.h"

namespace fluidcast::testing {

class ServerProcess {
 public:
  // `descriptors`: the process's limit on open files, soft and hard (0: as inherited).
  explicit ServerProcess(std::vector<std::string> flags = {}, rlim_t descriptors = 0) {
    int out[2];
    if (pipe(out) != 0) throw std::runtime_error("pipe failed");
    // Its own state folder (the page's self-signed certificate), not the person's home.
    std::string state = (std::filesystem::temp_directory_path() / "fluidcast-test-XXXXXX").string();
    if (!mkdtemp(state.data())) throw std::runtime_error("mkdtemp failed");
    state_ = state;
    std::vector<std::string> args = {FLUIDCAST_SERVER_PATH, "--http-port", "0", "--state-dir",
                                     state};
    const auto named = [&](const char* flag) {
      return std::find(flags.begin(), flags.end(), flag) != flags.end();
    };
    // Loopback, unless the flags name an address; any free port, unless they name one (a
    // restart on the same address).
    if (!named("--listen")) args.insert(args.end(), {"--listen", "127.0.0.1"});
    if (!named("--grpc-port")) args.insert(args.end(), {"--grpc-port", "0"});
    args.insert(args.end(), flags.begin(), flags.end());
    pid_ = fork();
    if (pid_ == 0) {
      if (descriptors) {
        const rlimit limit{descriptors, descriptors};
        setrlimit(RLIMIT_NOFILE, &limit);
      }
      dup2(out[1], STDOUT_FILENO);
      close(out[0]);
      std::vector<char*> argv;
      for (auto& arg : args) argv.push_back(arg.data());
      argv.push_back(nullptr);
      execv(argv[0], argv.data());
      _exit(127);
    }
    close(out[1]);
    output_ = fdopen(out[0], "r");
    char line[1024];
    const std::regex listening("grpc=([0-9a-f.:]+):([0-9]+) http=[0-9a-f.:]+:([0-9]+)");
    while (std::fgets(line, sizeof line, output_)) {
      std::cmatch match;
      if (std::regex_search(line, match, listening)) {
        grpc_address_ = match[1].str() + ":" + match[2].str();
        http_port_ = std::stoi(match[3].str());
        // Its log goes on being read, so that a long run never blocks it on a full pipe.
        drain_ = std::thread([output = output_] {
          char discarded[4096];
          while (std::fgets(discarded, sizeof discarded, output)) {
          }
        });
        return;
      }
    }
    throw std::runtime_error("fluidcast-server did not say where it listens");
  }

  ~ServerProcess() {
    if (pid_ > 0) stop();
    if (drain_.joinable()) drain_.join();  // the pipe ends with the process
    if (output_) fclose(output_);
    std::error_code ignored;
    std::filesystem::remove_all(state_, ignored);
  }

  // host:port as the server printed it (with --listen :: a client names an address instead).
  const std::string& grpc_address() const { return grpc_address_; }
  // Resident memory now, from /proc (kB).
  long resident_kb() const { return status_value("VmRSS: %ld kB"); }
  int http_port() const { return http_port_; }
  // The value of an unlabelled metric in its /metrics page now; -1 when the page or the name
  // is missing.
  double metric(const std::string& name) const {
    // A busy server may take seconds to answer: a missing page is for a server that is gone.
    const std::string page = RawConnection(http_port_, std::chrono::seconds(30)).page("/metrics");
    const auto at = page.find("\n" + name + " ");
    return at == std::string::npos ? -1 : std::stod(page.substr(at + name.size() + 2));
  }
  // Descriptors the process has open now, from /proc.
  long open_descriptors() const {
    std::error_code error;
    long count = 0;
    for (std::filesystem::directory_iterator it("/proc/" + std::to_string(pid_) + "/fd", error),
         end;
         !error && it != end; it.increment(error)) {
      ++count;
    }
    return error ? -1 : count;
  }
  // Its threads now, from /proc.
  long threads() const { return status_value("Threads: %ld"); }
  // How many of its threads have each name now (/proc/PID/task/*/comm: gRPC's, spdlog's, ours).
  std::map<std::string, int> thread_names() const {
    std::map<std::string, int> names;
    std::error_code error;
    for (std::filesystem::directory_iterator it("/proc/" + std::to_string(pid_) + "/task", error),
         end;
         !error && it != end; it.increment(error)) {
      std::ifstream comm(it->path() / "comm");
      std::string name;
      if (std::getline(comm, name)) ++names[name];
    }
    return names;
  }
  // CPU time the process has used (user and system), seconds.
  double cpu_seconds() const {
    std::FILE* stat = std::fopen(("/proc/" + std::to_string(pid_) + "/stat").c_str(), "r");
    if (!stat) return -1;
    unsigned long user = 0, system = 0;
    // Fields 14 and 15, after the command in parentheses (which has no spaces here).
    const int read = std::fscanf(
        stat, "%*d %*s %*c %*d %*d %*d %*d %*d %*u %*u %*u %*u %*u %lu %lu", &user, &system);
    std::fclose(stat);
    return read == 2 ? static_cast<double>(user + system) / sysconf(_SC_CLK_TCK) : -1;
  }

  // SIGTERM; returns the exit status (-1 when it did not exit normally).
  int stop() {
    if (pid_ <= 0) return exit_status_;
    kill(pid_, SIGTERM);
    int status = 0;
    waitpid(pid_, &status, 0);
    pid_ = -1;
    exit_status_ = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return exit_status_;
  }

 private:
  // The number in the line of /proc/PID/status that `format` (a scanf format) reads; -1 if none.
  long status_value(const char* format) const {
    std::FILE* status = std::fopen(("/proc/" + std::to_string(pid_) + "/status").c_str(), "r");
    if (!status) return -1;
    char line[256];
    long value = -1;
    while (std::fgets(line, sizeof line, status)) {
      if (std::sscanf(line, format, &value) == 1) break;
    }
    std::fclose(status);
    return value;
  }

  std::filesystem::path state_;
  pid_t pid_ = -1;
  FILE* output_ = nullptr;
  std::thread drain_;
  std::string grpc_address_;
  int http_port_ = 0;
  int exit_status_ = -1;
};

}  // namespace fluidcast::testing

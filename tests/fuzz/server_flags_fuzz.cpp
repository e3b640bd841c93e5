// Fuzz target: any bytes as fluidcast-server's command line (arguments split at NUL bytes), through
// the same parsing the server runs. A CLI::ParseError (help and version included) is the answer
// to bad flags, worded by exit_for; anything else escaping is a defect.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "options.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::vector<std::string> arguments{"fluidcast-server"};
  arguments.emplace_back();
  for (std::size_t k = 0; k < size; ++k) {
    if (data[k] == 0) {
      arguments.emplace_back();
    } else {
      arguments.back() += static_cast<char>(data[k]);
    }
  }
  std::vector<const char*> argv;
  for (const std::string& argument : arguments) argv.push_back(argument.c_str());
  CLI::App app;
  try {
    fluidcast::server::read_server_options(app, static_cast<int>(argv.size()), argv.data());
  } catch (const CLI::ParseError&) {
  }
  return 0;
}

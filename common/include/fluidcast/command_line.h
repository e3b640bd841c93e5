// How every fluidcast program treats its command line: --version prints the program and the
// project's version; --help prints the options; both exit 0. A bad flag or value prints one
// sentence naming it and exits kBadFlag.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "fluidcast/version.h"

namespace fluidcast {

inline constexpr int kBadFlag = 2;

inline void add_version_flag(CLI::App& app, const std::string& program) {
  app.set_version_flag("--version", program + " " + kVersion);
}

// For a CLI::ParseError from app.parse(): what CLI11 prints for it, and the exit code.
inline int exit_for(const CLI::App& app, const CLI::ParseError& error) {
  return app.exit(error) == 0 ? 0 : kBadFlag;
}

}  // namespace fluidcast

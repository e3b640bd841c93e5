// How every fluidcast program treats its command line: --version prints the program and the
// project's version; --help prints the options; both exit 0. A bad flag or value prints one
// sentence naming it and exits kBadFlag.
#pragma once

#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "fluidcast/version.h"

namespace fluidcast {

inline constexpr int kBadFlag = 2;

inline void add_version_flag(CLI::App& app, const std::string& program) {
  app.set_version_flag("--version", program + " " + kVersion);
}

// A floating-point flag's range: CLI::Range alone lets "nan" through (both of its comparisons are
// false), and "inf" where the range is open.
inline CLI::Validator finite_range(double low, double high) {
  const CLI::Range range(low, high);
  return CLI::Validator(
      [range](std::string& input) {
        double value = 0.0;
        if (!CLI::detail::lexical_cast(input, value) || !std::isfinite(value)) {
          return "Value " + input + " is not a finite number";
        }
        return range(input);
      },
      range.get_description());
}

// For a CLI::ParseError from app.parse(): what CLI11 prints for it, and the exit code. A bad value
// that came from an option's environment variable is said to come from there (a container's or a
// unit's settings are variables, not flags).
inline int exit_for(const CLI::App& app, const CLI::ParseError& error) {
  const std::string what = error.what();
  for (const CLI::Option* option : app.get_options()) {
    const std::string& variable = option->get_envname();
    const char* value = variable.empty() ? nullptr : std::getenv(variable.c_str());
    if (value && *value && what.find(option->get_name()) != std::string::npos &&
        what.find(value) != std::string::npos) {
      std::fprintf(stderr, "the environment variable %s (for %s) is not valid: %s\n",
                   variable.c_str(), option->get_name().c_str(), what.c_str());
      return kBadFlag;
    }
  }
  return app.exit(error) == 0 ? 0 : kBadFlag;
}

}  // namespace fluidcast

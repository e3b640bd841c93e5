// How every fluidcast program treats its command line: --version prints the program and the
// project's version; --help prints the options; both exit 0. A bad flag or value prints one
// sentence naming it and exits kBadFlag.
#pragma once

#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <set>
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

// Every setting of `app` as a Markdown table (flag, environment variable, default, values, what it
// does), for a program's settings in docs/: the values are the range or names --help gives, else
// the type.
// The options named in `said_defaults` have a default that depends on where the program is (a
// folder beside it): their description says it, the table shows none.
inline std::string settings_markdown(const CLI::App& app,
                                     const std::set<std::string>& said_defaults = {}) {
  const auto cell = [](std::string text) {
    std::string escaped;  // one row: no line breaks, and a | that is not a column's end
    for (const char c : text) {
      if (c == '|') escaped += '\\';
      escaped += c == '\n' ? ' ' : c;
    }
    return escaped.empty() ? std::string("–") : escaped;
  };
  const auto code = [](const std::string& text) {
    return text.empty() ? std::string() : "`" + text + "`";
  };
  std::string table =
      "| flag | variable | default | values | what |\n| --- | --- | --- | --- | --- |\n";
  for (const CLI::Option* option : app.get_options()) {
    if (option->get_envname().empty()) continue;       // --help, --version, --list-…: no setting
    const std::string type = option->get_type_name();  // "UINT:UINT in [1 - 8]": its checks
    const std::size_t checks = type.find(':');
    const std::string values = option->get_expected_max() == 0 ? "flag"
                               : checks == std::string::npos   ? type
                                                               : type.substr(checks + 1);
    const std::string fallback =
        said_defaults.count(option->get_name()) != 0 ? std::string() : option->get_default_str();
    table += "| " + code(option->get_name()) + " | " + code(option->get_envname()) + " | " +
             cell(code(fallback)) + " | " + cell(values) + " | " + cell(option->get_description()) +
             " |\n";
  }
  return table;
}

}  // namespace fluidcast

// The tools' command lines: one CLI option per tunable, bound to the field it describes, with its
// unit and range in the help. Values are checked by sim::validate after parsing.
#pragma once

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "fluidcast/sim/param_spec.h"

namespace fluidcast::tools {

template <class Owner>
void add_spec_options(CLI::App& app, Owner& owner,
                      const std::vector<sim::ParamSpec<Owner>>& specs) {
  for (const auto& spec : specs) {
    const std::string flag = "--" + std::string(spec.name);
    const std::string help = std::string(spec.description) + " [" + std::string(spec.unit) +
                             ", range " + sim::format_range(spec.min, spec.max) + "]";
    std::visit(
        [&](auto member) { app.add_option(flag, owner.*member, help)->capture_default_str(); },
        spec.member);
  }
}

}  // namespace fluidcast::tools

#include "fluidcast/sim/param_spec.h"

namespace fluidcast::sim {
namespace {

// `text` with each {name} in it as `name_of` says it.
std::string substitute(const std::string& text,
                       const std::function<std::string(std::string_view)>& name_of) {
  std::string out;
  for (std::size_t at = 0; at < text.size();) {
    const std::size_t open = text.find('{', at);
    const std::size_t close = open == std::string::npos ? open : text.find('}', open);
    if (close == std::string::npos) {
      out.append(text, at);
      break;
    }
    out.append(text, at, open - at);
    out += name_of(std::string_view(text).substr(open + 1, close - open - 1));
    at = close + 1;
  }
  return out;
}

std::string as_flag(std::string_view name) {
  std::string flag("--");
  flag.append(name);
  return flag;
}

}  // namespace

ParamError::ParamError(std::string text)
    : std::invalid_argument(substitute(text, as_flag)), text_(std::move(text)) {}

std::string ParamError::worded(
    const std::function<std::string(std::string_view name)>& name_of) const {
  return substitute(text_, name_of);
}

}  // namespace fluidcast::sim

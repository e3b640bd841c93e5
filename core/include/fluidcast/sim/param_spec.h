// Declares a tunable once — name, unit, description, default and range — so that the CLI, the
// validation, the protocol and docs/tuning.md all read the same table.
#pragma once

#include <cmath>
#include <functional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

namespace fluidcast::sim {

// A value outside its declared range, not finite, or at odds with another. Its text names the
// parameters in braces, by their names ("{column-width}: must be less than {tank-length}"), and
// each front end words them for its reader: what() as the command line's flags (--column-width),
// worded() in any other way (the server says which field of a message, or its own setting).
class ParamError : public std::invalid_argument {
 public:
  explicit ParamError(std::string text);
  std::string worded(const std::function<std::string(std::string_view name)>& name_of) const;

 private:
  std::string text_;
};

template <class Owner>
struct ParamSpec {
  std::string_view name;  // the CLI flag without dashes, e.g. "xsph-viscosity"
  std::string_view unit;  // SI unit, or "1" when dimensionless
  std::string_view description;
  std::variant<float Owner::*, int Owner::*> member;
  double min;
  double max;

  double get(const Owner& owner) const {
    return std::visit([&](auto field) { return static_cast<double>(owner.*field); }, member);
  }
  bool is_integer() const { return std::holds_alternative<int Owner::*>(member); }
};

// A whole number in full (16777216, not 1.67772e+07), any other in six significant digits.
inline std::string format_number(double x) {
  std::ostringstream out;
  if (std::isfinite(x) && x == std::floor(x) && std::fabs(x) < 0x1p53) {
    out << static_cast<long long>(x);
  } else {
    out << x;
  }
  return out.str();
}

inline std::string format_range(double min, double max) {
  return '[' + format_number(min) + ", " + format_number(max) + ']';
}

// Throws ParamError("{name}: value V ...; accepted range [min, max] unit") for the first bad value.
template <class Owner>
void validate(const Owner& owner, const std::vector<ParamSpec<Owner>>& specs) {
  for (const auto& spec : specs) {
    const double value = spec.get(owner);
    // A float field is compared as a float: set to a bound (0.1) it holds the float nearest it,
    // which may lie just outside the bound as a double.
    const auto stored = [&](double x) {
      return spec.is_integer() ? x : static_cast<double>(static_cast<float>(x));
    };
    if (!std::isfinite(value) || stored(value) < stored(spec.min) ||
        stored(value) > stored(spec.max)) {
      std::ostringstream out;
      out << '{' << spec.name << "}: value " << format_number(value)
          << (std::isfinite(value) ? " is out of range" : " is not a finite number")
          << "; accepted range " << format_range(spec.min, spec.max) << ' ' << spec.unit;
      throw ParamError(out.str());
    }
  }
}

// The index of `name` in `names`; otherwise throws
// ParamError("{flag}: unknown <what> 'name'; expected one of a, b, c").
inline std::size_t index_of_name(const std::vector<std::string_view>& names, std::string_view name,
                                 std::string_view flag, std::string_view what) {
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (names[i] == name) return i;
  }
  std::string list;
  for (auto n : names) list += (list.empty() ? "" : ", ") + std::string(n);
  std::string text = "{";  // appended, not +: GCC 12 warns about "{" + std::string (-Wrestrict)
  text.append(flag).append("}: unknown ").append(what).append(" '").append(name);
  throw ParamError(text.append("'; expected one of ").append(list));
}

// A Markdown table of the specs with the defaults of `defaults`: the body of docs/tuning.md.
template <class Owner>
std::string describe_markdown(const Owner& defaults, const std::vector<ParamSpec<Owner>>& specs) {
  std::ostringstream out;
  out << "| flag | unit | default | range | meaning |\n|---|---|---|---|---|\n";
  for (const auto& spec : specs) {
    out << "| `--" << spec.name << "` | " << spec.unit << " | " << format_number(spec.get(defaults))
        << " | " << format_range(spec.min, spec.max) << " | " << spec.description << " |\n";
  }
  return out.str();
}

}  // namespace fluidcast::sim

#include "svg_plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace fluidcast::validation {
namespace {

// The smallest of 1, 2, 5 × 10^k at or above `value` / 5: a tick spacing giving about five ticks.
double tick_spacing(double extent) {
  const double rough = extent / 5.0;
  const double decade = std::pow(10.0, std::floor(std::log10(rough)));
  for (const double m : {1.0, 2.0, 5.0, 10.0}) {
    if (m * decade >= rough) return m * decade;
  }
  return 10.0 * decade;
}

struct Axis {
  double low = 0.0, high = 1.0, tick = 0.2;
  explicit Axis(const std::vector<const std::vector<double>*>& values) {
    double smallest = 0.0, largest = 0.0;
    for (const auto* v : values) {
      for (const double x : *v) {
        if (!std::isfinite(x)) continue;
        smallest = std::min(smallest, x);
        largest = std::max(largest, x);
      }
    }
    if (largest <= smallest) largest = smallest + 1.0;
    tick = tick_spacing(largest - smallest);
    low = std::floor(smallest / tick) * tick;
    high = std::ceil(largest / tick) * tick;
  }
};

std::string number(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", std::abs(value) < 1e-12 ? 0.0 : value);
  return text;
}

std::string escape(const std::string& text) {
  std::string out;
  for (const char c : text) {
    if (c == '<') out += "&lt;";
    else if (c == '>') out += "&gt;";
    else if (c == '&') out += "&amp;";
    else out += c;
  }
  return out;
}

}  // namespace

std::string to_svg(const Chart& chart, int width, int height) {
  std::vector<const std::vector<double>*> xs, ys;
  for (const Series& s : chart.series) {
    xs.push_back(&s.x);
    ys.push_back(&s.y);
  }
  const Axis ax(xs), ay(ys);
  const double left = 80, right = width - 180.0, top = 50, bottom = height - 60.0;
  const auto px = [&](double x) { return left + (x - ax.low) / (ax.high - ax.low) * (right - left); };
  const auto py = [&](double y) { return bottom - (y - ay.low) / (ay.high - ay.low) * (bottom - top); };

  std::ostringstream svg;
  svg << "<svg xmlns='http://www.w3.org/2000/svg' width='" << width << "' height='" << height
      << "' font-family='sans-serif' font-size='14'>\n"
      << "<rect width='100%' height='100%' fill='white'/>\n"
      << "<text x='" << left << "' y='30' font-size='17'>" << escape(chart.title) << "</text>\n";
  for (double x = ax.low; x <= ax.high + 1e-9 * ax.tick; x += ax.tick) {
    svg << "<line x1='" << px(x) << "' y1='" << top << "' x2='" << px(x) << "' y2='" << bottom
        << "' stroke='#ddd'/><text x='" << px(x) << "' y='" << bottom + 20
        << "' text-anchor='middle'>" << number(x) << "</text>\n";
  }
  for (double y = ay.low; y <= ay.high + 1e-9 * ay.tick; y += ay.tick) {
    svg << "<line x1='" << left << "' y1='" << py(y) << "' x2='" << right << "' y2='" << py(y)
        << "' stroke='#ddd'/><text x='" << left - 8 << "' y='" << py(y) + 5
        << "' text-anchor='end'>" << number(y) << "</text>\n";
  }
  svg << "<rect x='" << left << "' y='" << top << "' width='" << right - left << "' height='"
      << bottom - top << "' fill='none' stroke='black'/>\n"
      << "<text x='" << (left + right) / 2 << "' y='" << height - 15 << "' text-anchor='middle'>"
      << escape(chart.x_label) << "</text>\n"
      << "<text transform='translate(22," << (top + bottom) / 2
      << ") rotate(-90)' text-anchor='middle'>" << escape(chart.y_label) << "</text>\n";
  for (std::size_t k = 0; k < chart.series.size(); ++k) {
    const Series& s = chart.series[k];
    const std::size_t n = std::min(s.x.size(), s.y.size());
    if (s.markers) {
      for (std::size_t i = 0; i < n; ++i) {
        svg << "<circle cx='" << px(s.x[i]) << "' cy='" << py(s.y[i]) << "' r='4' fill='none' "
            << "stroke='" << s.colour << "' stroke-width='2'/>\n";
      }
    } else if (n > 0) {
      svg << "<polyline fill='none' stroke='" << s.colour << "' stroke-width='2' points='";
      for (std::size_t i = 0; i < n; ++i) svg << px(s.x[i]) << ',' << py(s.y[i]) << ' ';
      svg << "'/>\n";
    }
    const double ly = top + 20.0 + 24.0 * static_cast<double>(k);
    svg << "<line x1='" << right + 12 << "' y1='" << ly - 5 << "' x2='" << right + 36 << "' y2='"
        << ly - 5 << "' stroke='" << s.colour << "' stroke-width='" << (s.markers ? 0 : 2)
        << "'/>";
    if (s.markers) {
      svg << "<circle cx='" << right + 24 << "' cy='" << ly - 5 << "' r='4' fill='none' stroke='"
          << s.colour << "' stroke-width='2'/>";
    }
    svg << "<text x='" << right + 42 << "' y='" << ly << "'>" << escape(s.label) << "</text>\n";
  }
  svg << "</svg>\n";
  return svg.str();
}

}  // namespace fluidcast::validation

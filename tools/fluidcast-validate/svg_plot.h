// A line-and-marker chart as SVG text: enough to look at a validation run (a browser, or
// Chromium headless, turns it into PNG).
#pragma once

#include <string>
#include <vector>

namespace fluidcast::validation {

struct Series {
  std::string label;
  std::string colour;  // CSS colour
  bool markers = false;  // circles at the points instead of a line through them
  std::vector<double> x, y;
};

struct Chart {
  std::string title, x_label, y_label;
  std::vector<Series> series;
};

// Axes from 0 (or the smallest value, if negative) to a round number above the largest.
std::string to_svg(const Chart& chart, int width = 800, int height = 500);

}  // namespace fluidcast::validation

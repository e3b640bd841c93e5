#include "martin_moyce.h"

#include <algorithm>
#include <cmath>

namespace fluidcast::validation {
namespace {

// Table 2 (p. 317), rectangular section, n² = 2, a = 2.25 in, means of the runs. Up to Z = 4.11
// the same values are in Ocellaris's and Lethe's validation scripts (Ocellaris has T = 2.98 at
// Z = 3.67); PySPH's digitization of their Fig. 3 agrees within 0.05 in T over the whole range,
// the last two points included ((4.03, 4.94) and (4.42, 5.88) there).
constexpr FrontPoint kTable2[] = {
    {0.41, 1.11}, {0.84, 1.22}, {1.19, 1.44}, {1.43, 1.67}, {1.63, 1.89}, {1.83, 2.11},
    {1.98, 2.33}, {2.20, 2.56}, {2.32, 2.78}, {2.51, 3.00}, {2.65, 3.22}, {2.83, 3.44},
    {2.97, 3.67}, {3.11, 3.89}, {3.33, 4.11}, {4.02, 5.00}, {4.44, 5.89},
};

constexpr FrontPoint kReference{1.19, 1.44};  // the point every run was shifted to pass

// Linear interpolation of Z at T; nullopt-free: the caller checks T is covered.
double z_at(std::span<const FrontPoint> points, double T) {
  const auto after = std::lower_bound(points.begin(), points.end(), T,
                                      [](const FrontPoint& p, double t) { return p.T < t; });
  if (after == points.begin()) return after->Z;
  const FrontPoint& b = *after;
  const FrontPoint& a = *(after - 1);
  const double w = b.T > a.T ? (T - a.T) / (b.T - a.T) : 1.0;
  return a.Z + w * (b.Z - a.Z);
}

}  // namespace

std::span<const FrontPoint> martin_moyce_n2_front() { return kTable2; }

FrontPoint to_martin_moyce(double t, double x, double a, double gravity, double n) {
  return {n * t * std::sqrt(gravity / a), x / a};
}

double shift_as_martin_and_moyce(std::span<const FrontPoint> simulated) {
  for (std::size_t k = 1; k < simulated.size(); ++k) {
    const FrontPoint& a = simulated[k - 1];
    const FrontPoint& b = simulated[k];
    if (a.Z < kReference.Z && b.Z >= kReference.Z) {
      const double w = (kReference.Z - a.Z) / (b.Z - a.Z);
      return kReference.T - (a.T + w * (b.T - a.T));
    }
  }
  return 0.0;
}

FrontComparison compare_fronts(std::span<const FrontPoint> simulated,
                               std::span<const FrontPoint> experiment, double shift, double t_max) {
  FrontComparison c;
  if (simulated.empty()) return c;
  std::vector<FrontPoint> shifted(simulated.begin(), simulated.end());
  for (FrontPoint& p : shifted) p.T += shift;
  double sum = 0.0;
  for (const FrontPoint& e : experiment) {
    if (e.T > t_max || e.T < shifted.front().T || e.T > shifted.back().T) continue;
    const double error = std::abs(z_at(shifted, e.T) - e.Z) / e.Z;
    sum += error;
    c.worst_relative_error = std::max(c.worst_relative_error, error);
    ++c.points;
  }
  if (c.points > 0) c.mean_relative_error = sum / static_cast<double>(c.points);
  return c;
}

}  // namespace fluidcast::validation

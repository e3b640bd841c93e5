// The collapse of a water column against the experiment it is always checked against:
// J. C. Martin and W. J. Moyce, "An experimental study of the collapse of liquid columns on a
// rigid horizontal plane", Phil. Trans. R. Soc. London A 244 (1952) 312–324.
#pragma once

#include <span>
#include <vector>

namespace fluidcast::validation {

// A surge-front position in Martin & Moyce's variables for a column of base width a and height
// n²·a: Z = x / a (x from the back wall) against T = n · t · √(g / a).
struct FrontPoint {
  double T;
  double Z;
};

// Their Table 2, n² = 2, a = 2.25 in: the printed means of the runs, T ≤ 4.44 (Z ≤ 5.89). Their
// runs' clocks were shifted so that T = 1.19 at Z = 1.44 (the gate's release is not instant).
std::span<const FrontPoint> martin_moyce_n2_front();

// Z and T of the experiment for a simulated front x (m) at time t (s), column width a (m).
FrontPoint to_martin_moyce(double t, double x, double a, double gravity, double n);

// The shift to add to a simulated T so that it passes Z = 1.44 at T = 1.19, as the experiment's
// runs were shifted; 0 when the simulation never reaches Z = 1.44. `simulated` in increasing T.
double shift_as_martin_and_moyce(std::span<const FrontPoint> simulated);

struct FrontComparison {
  double mean_relative_error = 0.0;  // mean over experimental points of |Z_sim − Z| / Z
  double worst_relative_error = 0.0;
  std::size_t points = 0;            // experimental points compared
};

// The simulated front (in increasing T, shifted by `shift`) interpolated at each experimental
// point with T ≤ t_max that the simulation covers.
FrontComparison compare_fronts(std::span<const FrontPoint> simulated,
                               std::span<const FrontPoint> experiment, double shift, double t_max);

}  // namespace fluidcast::validation

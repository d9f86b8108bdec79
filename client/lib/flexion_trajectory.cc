#include "flexion_trajectory.h"

#include <cmath>

namespace deform::client {

double FlexionDegreesAt(double t_seconds, double cycle_seconds, double peak_degrees) {
  constexpr double kTwoPi = 6.283185307179586;
  return 0.5 * peak_degrees * (1.0 - std::cos(kTwoPi * t_seconds / cycle_seconds));
}

}  // namespace deform::client

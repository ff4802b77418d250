#include "receiver/chi_square.hpp"

#include <cmath>

namespace ultratrack::receiver {

double normal_upper_quantile(double p) {
  // Bisection on the upper tail 0.5 erfc(z / sqrt 2): monotone, 60 halvings reach double precision.
  double lo = -40.0, hi = 40.0;
  for (int i = 0; i < 100; ++i) {
    const double mid = 0.5 * (lo + hi);
    if (0.5 * std::erfc(mid / std::sqrt(2.0)) > p) {
      lo = mid;
    } else {
      hi = mid;
    }
  }
  return 0.5 * (lo + hi);
}

double chi_square_quantile(int dof, double p) {
  if (dof == 1) {
    const double z = normal_upper_quantile(0.5 * p);
    return z * z;
  }
  if (dof == 2) return -2.0 * std::log(p);
  const double k = dof;
  const double z = normal_upper_quantile(p);
  const double c = 1.0 - 2.0 / (9.0 * k) + z * std::sqrt(2.0 / (9.0 * k));
  return k * c * c * c;
}

}  // namespace ultratrack::receiver

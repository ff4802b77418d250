// SPDX-License-Identifier: GPL-3.0-or-later
#include "fusion/fix_error_model.hpp"

namespace ultratrack::fusion {

bool FixErrorOptions::IsValid(std::string* why) const {
  auto fail = [&](const char* m) {
    if (why) *why = m;
    return false;
  };
  if (!(correlation_time_s > 0.0) || !std::isfinite(correlation_time_s))
    return fail("fix error: the correlation time must be positive");
  if (!((sigma_ned_m.array() > 0.0).all() && sigma_ned_m.allFinite()))
    return fail("fix error: the Gauss-Markov sigmas must be positive");
  if (!(min_white_fraction > 0.0 && min_white_fraction <= 1.0))
    return fail("fix error: the minimum white fraction must lie in (0, 1]");
  return true;
}

double fix_error_transition(double dt, double tau_s, Discretisation method) {
  const double a = dt / tau_s;
  return method == Discretisation::VanLoan ? std::exp(-a) : 1.0 - a + 0.5 * a * a;
}

Eigen::Vector3d fix_white_sigma(const Eigen::Vector3d& sigma_fix, const FixErrorOptions& o) {
  const Eigen::Vector3d white2 =
      (sigma_fix.cwiseAbs2() - o.sigma_ned_m.cwiseAbs2()).cwiseMax((o.min_white_fraction * sigma_fix).cwiseAbs2());
  return white2.cwiseSqrt();
}

}  // namespace ultratrack::fusion

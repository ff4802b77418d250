// The chi-square distribution for gating and consistency tests: CDF through the regularised lower
// incomplete gamma function (series / continued fraction, ~1e-12) and its quantile by safeguarded bisection.
#pragma once

namespace ultratrack::fusion {

// P(X <= x) for X ~ chi-square with dof degrees of freedom (dof >= 1).
double chi_square_cdf(double x, int dof);
// The x with P(X <= x) = p, 0 < p < 1.
double chi_square_quantile(double p, int dof);

}  // namespace ultratrack::fusion

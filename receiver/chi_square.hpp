// SPDX-License-Identifier: GPL-3.0-or-later
// The chi-square distribution of every statistical test in the tree (PVT and snapshot residual tests, the attitude
// solver's gates, the filters' innovation gates, consistency bands): exact, through the regularised incomplete gamma
// functions (series / Lentz continued fraction, relative error ~1e-12), each tail computed directly so that a small
// false-alarm probability keeps its precision. Every function takes the degrees of freedom first and names its tail.
#pragma once

namespace ultratrack::receiver {

// P(X <= x) for X ~ chi-square(dof); dof >= 1 (std::invalid_argument otherwise).
double chi_square_cdf(int dof, double x);
// P(X > x).
double chi_square_upper_tail(int dof, double x);
// The x with P(X > x) = upper_tail_probability (a test's threshold at that false-alarm probability), in (0, 1).
double chi_square_upper_quantile(int dof, double upper_tail_probability);
// The x with P(X <= x) = lower_tail_probability, in (0, 1).
double chi_square_lower_quantile(int dof, double lower_tail_probability);

// z with P(N(0,1) > z) = upper_tail_probability.
double normal_upper_quantile(double upper_tail_probability);

}  // namespace ultratrack::receiver

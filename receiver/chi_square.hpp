// Chi-square quantiles for the statistical gates of the attitude solver (ratio/residual tests): exact for 1 and 2
// degrees of freedom, Wilson-Hilferty (1931) cube-root normal approximation above (relative error < 1 % there).
#pragma once

namespace ultratrack::receiver {

// x with P(chi2_dof > x) = upper_tail_probability; dof >= 1, probability in (0, 1).
double chi_square_quantile(int dof, double upper_tail_probability);

// z with P(N(0,1) > z) = upper_tail_probability.
double normal_upper_quantile(double upper_tail_probability);

}  // namespace ultratrack::receiver

// SPDX-License-Identifier: GPL-3.0-or-later
#include "receiver/chi_square.hpp"

#include <cmath>
#include <stdexcept>

namespace ultratrack::receiver {
namespace {

struct GammaTails {
  double lower = 0.0, upper = 1.0;  // regularised P(a, x) and Q(a, x)
};

// Series for x < a + 1 (P directly), Lentz continued fraction otherwise (Q directly); the other as 1 minus it.
GammaTails gamma_tails(double a, double x) {
  if (x <= 0.0) return {0.0, 1.0};
  const double log_prefactor = a * std::log(x) - x - std::lgamma(a);
  if (x < a + 1.0) {
    double term = 1.0 / a, sum = term;
    for (int n = 1; n < 10000; ++n) {
      term *= x / (a + n);
      sum += term;
      if (std::abs(term) < std::abs(sum) * 1e-16) break;
    }
    const double p = sum * std::exp(log_prefactor);
    return {p, 1.0 - p};
  }
  const double tiny = 1e-300;
  double b = x + 1.0 - a, c = 1.0 / tiny, d = 1.0 / b, h = d;
  for (int i = 1; i < 10000; ++i) {
    const double an = -i * (i - a);
    b += 2.0;
    d = an * d + b;
    if (std::abs(d) < tiny) d = tiny;
    c = b + an / c;
    if (std::abs(c) < tiny) c = tiny;
    d = 1.0 / d;
    const double delta = d * c;
    h *= delta;
    if (std::abs(delta - 1.0) < 1e-16) break;
  }
  const double q = std::exp(log_prefactor) * h;
  return {1.0 - q, q};
}

void check(int dof, double probability) {
  if (dof < 1) throw std::invalid_argument("chi-square: degrees of freedom must be at least 1");
  if (!(probability > 0.0 && probability < 1.0)) throw std::invalid_argument("chi-square: probability not in (0, 1)");
}

// Bisection on x for a tail that is monotone in x; `below(x)` is true while x is below the quantile.
template <typename Below>
double bisect(int dof, Below below) {
  double lo = 0.0, hi = dof + 10.0 * std::sqrt(2.0 * dof) + 50.0;
  while (below(hi)) hi *= 2.0;
  for (int i = 0; i < 200 && hi - lo > 1e-13 * hi; ++i) {
    const double mid = 0.5 * (lo + hi);
    (below(mid) ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace

double chi_square_cdf(int dof, double x) {
  if (dof < 1) throw std::invalid_argument("chi-square: degrees of freedom must be at least 1");
  return gamma_tails(0.5 * dof, 0.5 * x).lower;
}

double chi_square_upper_tail(int dof, double x) {
  if (dof < 1) throw std::invalid_argument("chi-square: degrees of freedom must be at least 1");
  return gamma_tails(0.5 * dof, 0.5 * x).upper;
}

double chi_square_upper_quantile(int dof, double upper_tail_probability) {
  check(dof, upper_tail_probability);
  return bisect(dof, [&](double x) { return chi_square_upper_tail(dof, x) > upper_tail_probability; });
}

double chi_square_lower_quantile(int dof, double lower_tail_probability) {
  check(dof, lower_tail_probability);
  return bisect(dof, [&](double x) { return chi_square_cdf(dof, x) < lower_tail_probability; });
}

double normal_upper_quantile(double upper_tail_probability) {
  // Bisection on the upper tail 0.5 erfc(z / sqrt 2): monotone, 100 halvings reach double precision.
  double lo = -40.0, hi = 40.0;
  for (int i = 0; i < 100; ++i) {
    const double mid = 0.5 * (lo + hi);
    (0.5 * std::erfc(mid / std::sqrt(2.0)) > upper_tail_probability ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace ultratrack::receiver

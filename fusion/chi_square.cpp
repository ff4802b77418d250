#include "fusion/chi_square.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

namespace ultratrack::fusion {
namespace {

// Regularised lower incomplete gamma P(a, x) (series for x < a + 1, Lentz continued fraction otherwise).
double gamma_p(double a, double x) {
  if (x <= 0.0) return 0.0;
  const double log_prefactor = a * std::log(x) - x - std::lgamma(a);
  if (x < a + 1.0) {
    double term = 1.0 / a, sum = term;
    for (int n = 1; n < 10000; ++n) {
      term *= x / (a + n);
      sum += term;
      if (std::abs(term) < std::abs(sum) * 1e-16) break;
    }
    return sum * std::exp(log_prefactor);
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
  return 1.0 - std::exp(log_prefactor) * h;
}

}  // namespace

double chi_square_cdf(double x, int dof) {
  if (dof < 1) throw std::invalid_argument("chi-square: dof must be at least 1");
  return gamma_p(0.5 * dof, 0.5 * x);
}

double chi_square_quantile(double p, int dof) {
  if (dof < 1 || !(p > 0.0 && p < 1.0)) throw std::invalid_argument("chi-square quantile: dof >= 1, 0 < p < 1");
  double lo = 0.0, hi = dof + 10.0 * std::sqrt(2.0 * dof) + 50.0;
  while (chi_square_cdf(hi, dof) < p) hi *= 2.0;
  for (int i = 0; i < 200 && hi - lo > 1e-13 * hi; ++i) {
    const double mid = 0.5 * (lo + hi);
    (chi_square_cdf(mid, dof) < p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace ultratrack::fusion

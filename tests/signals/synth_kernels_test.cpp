// SPDX-License-Identifier: GPL-3.0-or-later
// The synthesiser's Gaussian noise against the normal distribution's closed forms: moments and tail
// fractions P(|x| > k) = erfc(k / sqrt 2), from 4 million values; tolerances are 5 sigma of each estimate.
#include "signals/synth_kernels.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <vector>

namespace ultratrack::signals::synth {
namespace {

TEST(GaussianNoise, MomentsAndTailsAreNormal) {
  GaussianNoise g(42, 7);
  const int n = 4'000'000;
  double s1 = 0, s2 = 0, s4 = 0;
  int beyond[5] = {0, 0, 0, 0, 0};
  for (int i = 0; i < n; ++i) {
    const double x = g.next();
    s1 += x;
    s2 += x * x;
    s4 += x * x * x * x;
    for (int k = 1; k <= 4; ++k) beyond[k] += std::abs(x) > k;
  }
  EXPECT_NEAR(s1 / n, 0.0, 5 * std::sqrt(1.0 / n));
  EXPECT_NEAR(s2 / n, 1.0, 5 * std::sqrt(2.0 / n));
  EXPECT_NEAR(s4 / n, 3.0, 5 * std::sqrt(96.0 / n));
  for (int k = 1; k <= 4; ++k) {
    const double p = std::erfc(k / std::sqrt(2.0));
    EXPECT_NEAR(static_cast<double>(beyond[k]) / n, p, 5 * std::sqrt(p * (1 - p) / n)) << "k = " << k;
  }
}

TEST(GaussianNoise, SameSeedSameValuesWhateverTheCallSizes) {
  GaussianNoise a(3, 1), b(3, 1), c(4, 1);
  std::vector<std::complex<float>> x(1000), y(1000), z(1000);
  a.fill(x.data(), 1000, 2.0f, true);
  b.fill(y.data(), 333, 2.0f, true);
  b.fill(y.data() + 333, 667, 2.0f, true);
  c.fill(z.data(), 1000, 2.0f, true);
  EXPECT_EQ(x, y);
  EXPECT_NE(x, z);
}

}  // namespace
}  // namespace ultratrack::signals::synth

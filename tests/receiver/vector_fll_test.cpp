// SPDX-License-Identifier: GPL-3.0-or-later
// The vector FLL's pieces on the channel side (issue 7): the frequency discriminator a vector loop reads from two
// contiguous 20 ms epochs (receiver/vector_frequency_discriminator.hpp) against a Monte Carlo of the receiver's own
// discriminator on Gaussian-noise correlator sums, and the differential bit detection (BitAssembler) that keeps the
// navigation bits when the carrier is frequency- but not phase-locked.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <cstdio>
#include <random>

#include "receiver/bit_sync.hpp"
#include "receiver/discriminators.hpp"
#include "receiver/vector_frequency_discriminator.hpp"

namespace {

using ultratrack::receiver::kTwoPi;

// Two contiguous T = 20 ms prompts (middles dt = 20 ms apart) of a signal f0 Hz off the replica, a random data bit
// on each, complex Gaussian noise of unit variance per component: A^2 / 2 = C T / N0. The discriminator's output
// is f0 + noise: its variance must be the closed form within the sample variance's spread (sqrt(2 / n) = 0.7 % at
// n = 40000, 4 sigma ~3 %) plus the Costas formula's neglected terms: +-5 % from 25 to 45 dB-Hz (measured 0.998 to
// 1.047); its mean f0 within 4 sigma of the mean (4 sqrt(var / n)) from 27 dB-Hz up, while at 25 dB-Hz (T C/N0 =
// 6.3) noise reaching the +-12.5 Hz wrap pulls it ~3 % toward 0 (bound 5 %). f0 = 3 Hz (inside the range; the
// sinc loss over an epoch, 0.15 %, is neglected).
TEST(VectorFrequencyDiscriminator, VarianceMatchesMonteCarloOfTheReceiversDiscriminator) {
  std::mt19937 rng(11);
  std::normal_distribution<double> g(0.0, 1.0);
  std::bernoulli_distribution bit(0.5);
  const double t = 0.02, dt = 0.02, f0 = 3.0;
  for (double cn0_dbhz : {25.0, 27.0, 30.0, 35.0, 40.0, 45.0}) {
    const double cn0 = std::pow(10.0, cn0_dbhz / 10.0);
    const double a = std::sqrt(2.0 * cn0 * t);
    const int n = 40000;
    double sum = 0.0, sum2 = 0.0;
    for (int i = 0; i < n; ++i) {
      const double phase0 = kTwoPi * std::uniform_real_distribution<double>(0.0, 1.0)(rng);
      const double s1 = bit(rng) ? 1.0 : -1.0, s2 = bit(rng) ? 1.0 : -1.0;
      const std::complex<double> n1(g(rng), g(rng)), n2(g(rng), g(rng));
      const auto p1 = std::complex<float>(s1 * a * std::polar(1.0, phase0) + n1);
      const auto p2 = std::complex<float>(s2 * a * std::polar(1.0, phase0 + kTwoPi * f0 * dt) + n2);
      const double f = ultratrack::receiver::costas_phase_change_cycles(p1, p2) / dt;
      sum += f;
      sum2 += (f - f0) * (f - f0);
    }
    const double model = ultratrack::receiver::phase_change_frequency_variance_hz2(cn0, t, dt);
    const double mean = sum / n, ratio = sum2 / n / model;
    std::printf("%.0f dB-Hz: mean %.4f Hz (f0 %.1f), variance %.4f Hz^2, model %.4f Hz^2, ratio %.3f\n", cn0_dbhz, mean,
                f0, sum2 / n, model, ratio);
    if (cn0_dbhz >= 27.0) {
      EXPECT_NEAR(mean, f0, 4.0 * std::sqrt(model / n)) << cn0_dbhz;
    } else {
      EXPECT_NEAR(mean, f0, 0.05 * f0) << cn0_dbhz;
    }
    EXPECT_NEAR(ratio, 1.0, 0.05) << cn0_dbhz;
  }
}

// Noise-free: the discriminator gives the offset exactly anywhere inside +-1 / (4 dt) whatever the bits, and aliases
// by 1 / (2 dt) outside (the Costas ambiguity that bounds the FLL's commanded frequency error).
TEST(VectorFrequencyDiscriminator, RangeIsAQuarterCyclePerIntervalWhateverTheBits) {
  const double dt = 0.02;
  for (double f0 : {-12.0, -5.0, 0.0, 0.7, 9.0, 12.4}) {
    for (double s2 : {1.0, -1.0}) {
      const auto p1 = std::complex<float>(std::polar(10.0, 0.4));
      const auto p2 = std::complex<float>(s2 * std::polar(10.0, 0.4 + kTwoPi * f0 * dt));
      EXPECT_NEAR(ultratrack::receiver::costas_phase_change_cycles(p1, p2) / dt, f0, 1e-4) << f0 << " " << s2;
    }
  }
  const auto p1 = std::complex<float>(std::polar(10.0, 0.4));
  const auto p2 = std::complex<float>(std::polar(10.0, 0.4 + kTwoPi * 15.0 * dt));
  EXPECT_NEAR(ultratrack::receiver::costas_phase_change_cycles(p1, p2) / dt, 15.0 - 25.0, 1e-4);
}

// The same Monte Carlo for the change with the bits wiped (wiped_phase_change_cycles, the bits known: their sign
// product removed) against the Costas change on the same draws, where the vector FLL runs weak. The wiped
// output's mean stays within 7 % of f0 from 20 dB-Hz up (measured 0.95 x f0 at 20, 0.99 at 22; the mean's own
// noise is < 0.2 % of f0 at n = 40000), the Costas change's falls to 0.78 x at 22 and 0.56 x at 20 dB-Hz (bound:
// below 0.85 x there); the wiped variance is the Costas closed form within -5 / +25 % from 18 to 45 dB-Hz
// (measured 1.00-1.16: the arctangent's tails at 18-22 dB-Hz, which the (1 + 1 / (2 T C/N0)) term approximates).
TEST(VectorFrequencyDiscriminator, WipedChangeStaysUnbiasedWhereTheCostasChangeFollowsZero) {
  std::mt19937 rng(12);
  std::normal_distribution<double> g(0.0, 1.0);
  std::bernoulli_distribution bit(0.5);
  const double t = 0.02, dt = 0.02, f0 = 3.0;
  for (double cn0_dbhz : {18.0, 20.0, 22.0, 24.0, 30.0, 45.0}) {
    const double cn0 = std::pow(10.0, cn0_dbhz / 10.0);
    const double a = std::sqrt(2.0 * cn0 * t);
    const int n = 40000;
    double sum = 0.0, sum2 = 0.0, costas = 0.0;
    for (int i = 0; i < n; ++i) {
      const double phase0 = kTwoPi * std::uniform_real_distribution<double>(0.0, 1.0)(rng);
      const int s1 = bit(rng) ? 1 : -1, s2 = bit(rng) ? 1 : -1;
      const std::complex<double> n1(g(rng), g(rng)), n2(g(rng), g(rng));
      const auto p1 = std::complex<float>(s1 * a * std::polar(1.0, phase0) + n1);
      const auto p2 = std::complex<float>(s2 * a * std::polar(1.0, phase0 + kTwoPi * f0 * dt) + n2);
      const double f = ultratrack::receiver::wiped_phase_change_cycles(p1, p2, s1 * s2) / dt;
      sum += f;
      sum2 += (f - f0) * (f - f0);
      costas += ultratrack::receiver::costas_phase_change_cycles(p1, p2) / dt;
    }
    const double model = ultratrack::receiver::phase_change_frequency_variance_hz2(cn0, t, dt);
    const double mean = sum / n, ratio = sum2 / n / model, costas_mean = costas / n;
    std::printf("%.0f dB-Hz: wiped mean %.3f Hz, Costas mean %.3f Hz (f0 %.1f); wiped variance / model %.3f\n",
                cn0_dbhz, mean, costas_mean, f0, ratio);
    if (cn0_dbhz >= 20.0) {
      EXPECT_NEAR(mean, f0, 0.07 * f0) << cn0_dbhz;
    }
    if (cn0_dbhz <= 22.0) {
      EXPECT_LT(costas_mean, 0.85 * f0) << cn0_dbhz;
    }
    EXPECT_GT(ratio, 0.95) << cn0_dbhz;
    EXPECT_LT(ratio, 1.25) << cn0_dbhz;
  }
}

// Noise-free, the wiped change gives the offset exactly inside +-1 / (2 dt) (twice the Costas range), whatever the
// bits once they are known.
TEST(VectorFrequencyDiscriminator, WipedRangeIsHalfACyclePerInterval) {
  const double dt = 0.02;
  for (double f0 : {-24.0, -15.0, -5.0, 0.0, 9.0, 15.0, 24.9}) {
    for (int s2 : {1, -1}) {
      const auto p1 = std::complex<float>(std::polar(10.0, 0.4));
      const auto p2 = std::complex<float>(static_cast<double>(s2) * std::polar(10.0, 0.4 + kTwoPi * f0 * dt));
      EXPECT_NEAR(ultratrack::receiver::wiped_phase_change_cycles(p1, p2, s2) / dt, f0, 1e-3) << f0 << " " << s2;
    }
  }
}

// A 20 ms-epoch bit stream whose carrier phase turns by 0.1 cycle per bit (5 Hz left by an FLL) at 35 dB-Hz
// (Eb/N0 = 18 dB: a differential error has probability 0.5 exp(-63), none expected): differential detection
// returns every bit (the chain starts from a first bit whose phase, 0.2 rad, makes it right), while coherent
// detection (sign of I) is wrong for about half of them once the phase has turned past a quarter cycle.
TEST(BitAssembler, DifferentialDetectionKeepsTheBitsOfARotatingCarrier) {
  std::mt19937 rng(5);
  std::normal_distribution<double> g(0.0, 1.0);
  std::bernoulli_distribution bit(0.5);
  const double a = std::sqrt(2.0 * std::pow(10.0, 3.5) * 0.02);
  ultratrack::receiver::BitAssembler differential(0), coherent(0);
  differential.set_differential(true);
  int bits = 0, differential_errors = 0, coherent_errors = 0;
  for (int k = 0; k < 500; ++k) {
    const int value = bit(rng) ? 1 : -1;
    ultratrack::receiver::CorrelationEpoch e;
    e.first_code_period = 20 * k;
    e.num_code_periods = 20;
    e.first_sample = 40000LL * k;
    e.antenna[0].prompt =
        std::complex<float>(value * a * std::polar(1.0, 0.2 + kTwoPi * 0.1 * k) + std::complex<double>(g(rng), g(rng)));
    const auto d = differential.add(e);
    const auto c = coherent.add(e);
    ASSERT_TRUE(d && c);
    ++bits;
    differential_errors += d->value != value;
    coherent_errors += c->value != value;
    EXPECT_EQ(d->soft > 0.0f ? 1 : -1, d->value);
  }
  EXPECT_EQ(bits, 500);
  EXPECT_EQ(differential_errors, 0);
  EXPECT_GT(coherent_errors, 150);
}

}  // namespace

// SPDX-License-Identifier: GPL-3.0-or-later
// Discriminators, loop filters and lock detectors alone, against their closed forms.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdio>
#include <random>

#include "receiver/bit_sync.hpp"
#include "receiver/discriminators.hpp"
#include "receiver/lock_detectors.hpp"
#include "receiver/loop_filters.hpp"

using namespace ultratrack::receiver;

namespace {
std::complex<float> polar(double a, double cycles) { return std::complex<float>(std::polar(a, 2 * M_PI * cycles)); }
double triangle(double x) { return std::max(0.0, 1.0 - std::abs(x)); }

// The carrier loop closed as the channel closes it: the NCO frequency computed from epoch k's average phase
// error drives epoch k+1; phases in cycles. Returns the average replica phase of each epoch.
std::vector<double> closed_loop(CarrierLoopFilter& f, double t, const std::vector<double>& input_avg_phase) {
  std::vector<double> out;
  double start = 0.0, freq = f.frequency_hz();
  for (double theta : input_avg_phase) {
    const double avg = start + freq * t / 2;
    out.push_back(avg);
    const double next = f.update(theta - avg, 0.0, t);
    start += freq * t;
    freq = next;
  }
  return out;
}

// One-sided noise bandwidth of the closed loop from its impulse response: Bn = sum h^2 / (2 T).
double noise_bandwidth(int order, double bw, double t) {
  CarrierLoopFilter f(order, bw, 0.0, 0.0);
  std::vector<double> impulse(static_cast<std::size_t>(60.0 / t), 0.0);
  impulse[0] = 1.0;
  double s2 = 0.0;
  for (double h : closed_loop(f, t, impulse)) s2 += h * h;
  return s2 / (2 * t);
}
}  // namespace

TEST(Discriminators, CostasAtanIsPhaseErrorAndIgnoresDataSign) {
  for (double c = -0.24; c <= 0.24; c += 0.02) {
    EXPECT_NEAR(costas_atan_cycles(polar(3.0, c)), c, 1e-7);
    EXPECT_NEAR(costas_atan_cycles(-polar(3.0, c)), c, 1e-7);
    EXPECT_NEAR(pll_atan2_cycles(polar(3.0, 2 * c)), 2 * c, 1e-7);
  }
}

TEST(Discriminators, FllCrossDotIsFrequencyError) {
  const double dt = 0.5e-3;
  for (double f = -900.0; f <= 900.0; f += 75.0) {
    EXPECT_NEAR(fll_atan2_hz(polar(2.0, 0.1), polar(2.0, 0.1 + f * dt), dt), f, 1e-3);
    if (std::abs(f) < 0.25 / dt) {
      EXPECT_NEAR(fll_atan_hz(polar(2.0, 0.1), -polar(2.0, 0.1 + f * dt), dt), f, 1e-3);
    }
  }
}

TEST(Discriminators, NormalisedEarlyMinusLateIsCodeErrorOnTheTriangle) {
  for (double d : {0.5, 0.25, 0.1}) {
    for (double tau = -d; tau <= d + 1e-12; tau += d / 5) {
      // early tap reads the code d chips ahead: its correlation is the triangle at tau - d
      const auto e = std::complex<float>(static_cast<float>(triangle(tau - d)), 0.0f);
      const auto l = std::complex<float>(static_cast<float>(triangle(tau + d)), 0.0f);
      EXPECT_NEAR(dll_nelp_chips(e, l, d), tau, 1e-6) << "d " << d;
    }
  }
}

TEST(LoopFilters, NoiseBandwidthMatchesDesignForSmallBnT) {
  EXPECT_NEAR(noise_bandwidth(2, 15.0, 1e-3), 15.0, 0.05 * 15.0);
  EXPECT_NEAR(noise_bandwidth(3, 15.0, 1e-3), 15.0, 0.05 * 15.0);
  EXPECT_NEAR(noise_bandwidth(3, 18.0, 1e-3), 18.0, 0.05 * 18.0);
  // Documented widening at larger Bn*T (20 ms epochs).
  EXPECT_NEAR(noise_bandwidth(3, 5.0, 20e-3), 5.0 * 1.2, 0.05 * 5.0);
  EXPECT_NEAR(noise_bandwidth(3, 10.0, 20e-3), 10.0 * 1.55, 0.05 * 10.0);
}

TEST(LoopFilters, SecondOrderTracksFrequencyStepAndLagsRampByClosedForm) {
  const double t = 1e-3, bw = 15.0;
  const double w0 = bw / kSecondOrderBnPerW0;
  // Frequency step of 20 Hz (phase ramp): no steady-state phase error.
  {
    CarrierLoopFilter f(2, bw, 0.0, 0.0);
    std::vector<double> in;
    for (int k = 0; k < 3000; ++k) in.push_back(20.0 * (k + 0.5) * t);
    const auto out = closed_loop(f, t, in);
    EXPECT_NEAR(in.back() - out.back(), 0.0, 1e-6);
  }
  // Frequency ramp of 50 Hz/s (phase acceleration): steady-state error = fdot / w0^2 cycles (Kaplan 5.4).
  {
    CarrierLoopFilter f(2, bw, 0.0, 0.0);
    std::vector<double> in;
    for (int k = 0; k < 5000; ++k) in.push_back(0.5 * 50.0 * std::pow((k + 0.5) * t, 2) + 50.0 * t * t / 24);
    const auto out = closed_loop(f, t, in);
    EXPECT_NEAR(in.back() - out.back(), 50.0 / (w0 * w0), 0.02 * 50.0 / (w0 * w0));
  }
}

TEST(LoopFilters, ThirdOrderTracksFrequencyRampAndLagsJerkByClosedForm) {
  const double t = 1e-3, bw = 15.0;
  const double w0 = bw / kThirdOrderBnPerW0;
  {
    CarrierLoopFilter f(3, bw, 0.0, 0.0);
    std::vector<double> in;
    for (int k = 0; k < 6000; ++k) in.push_back(0.5 * 50.0 * std::pow((k + 0.5) * t, 2) + 50.0 * t * t / 24);
    const auto out = closed_loop(f, t, in);
    EXPECT_NEAR(in.back() - out.back(), 0.0, 1e-5);
  }
  {
    // Frequency acceleration of 30 Hz/s^2: steady-state error = fddot / w0^3 cycles.
    CarrierLoopFilter f(3, bw, 0.0, 0.0);
    std::vector<double> in;
    for (int k = 0; k < 8000; ++k) {
      const double a = k * t, b = (k + 1) * t;  // epoch average of 30 t^3 / 6
      in.push_back(30.0 / 24 * (b * b * b * b - a * a * a * a) / t);
    }
    const auto out = closed_loop(f, t, in);
    EXPECT_NEAR(in.back() - out.back(), 30.0 / (w0 * w0 * w0), 0.03 * 30.0 / (w0 * w0 * w0));
  }
}

TEST(LoopFilters, FllAssistRemovesFrequencyErrorWithoutPhaseInput) {
  // Pure FLL (phase input zero): the frequency converges to the true one at the FLL's rate.
  for (int order : {2, 3}) {
    CarrierLoopFilter f(order, 15.0, 10.0, 0.0);
    double freq = 0.0;
    for (int k = 0; k < 2000; ++k) freq = f.update(0.0, 200.0 - freq, 1e-3);
    EXPECT_NEAR(freq, 200.0, 0.5) << "order " << order;
  }
}

TEST(LockDetectors, PhaseLockIndicatorIsCosTwiceThePhaseError) {
  for (double dphi : {0.0, 0.05, 0.125, 0.2}) {
    PhaseLockIndicator pli(0.1);
    for (int k = 0; k < 500; ++k) pli.update(polar(100.0, dphi) * (k % 3 == 0 ? -1.0f : 1.0f), 0.0, 1e-3);
    EXPECT_NEAR(pli.value(), std::cos(4 * M_PI * dphi), 1e-6);
  }
  // With noise and its power given, the indicator stays unbiased: SNR 3 (35 dB-Hz at 1 ms).
  std::mt19937 rng(5);
  std::normal_distribution<double> g(0.0, std::sqrt(0.5));
  PhaseLockIndicator pli(1.0);
  double mean = 0.0;
  for (int k = 0; k < 20000; ++k) {
    const auto p =
        polar(std::sqrt(3.0), 0.05) + std::complex<float>(static_cast<float>(g(rng)), static_cast<float>(g(rng)));
    pli.update(p, 1.0, 1e-3);
    if (k >= 10000) mean += pli.value() / 10000;
  }
  EXPECT_NEAR(mean, std::cos(4 * M_PI * 0.05), 0.05);
}

TEST(LockDetectors, Cn0EstimatorsAreUnbiasedAt45And35DbHz) {
  for (auto method : {Cn0Method::kMoments, Cn0Method::kNoiseTap}) {
    for (double cn0 : {45.0, 35.0}) {
      for (double t : {1e-3, 20e-3}) {
        std::mt19937 rng(17);
        std::normal_distribution<double> g(0.0, std::sqrt(0.5));  // E|n|^2 = 1
        std::bernoulli_distribution bit(0.5);
        const double s = std::sqrt(std::pow(10.0, cn0 / 10) * t);  // |P|^2 / E|n|^2 = C/N0 * T
        Cn0Estimator est(method, 200);
        double sum = 0.0;
        int n = 0;
        for (int k = 0; k < 200 * 50; ++k) {
          const auto noise = [&] {
            return std::complex<float>(static_cast<float>(g(rng)), static_cast<float>(g(rng)));
          };
          const auto p = polar(bit(rng) ? s : -s, 0.03 * k) + noise();
          if (auto v = est.add(p, noise(), t)) {
            sum += *v;
            ++n;
          }
        }
        ASSERT_EQ(n, 50);
        EXPECT_NEAR(sum / n, cn0, 0.3) << "method " << static_cast<int>(method) << " T " << t;
      }
    }
  }
}

TEST(BitSync, HistogramFindsTheEdgeAt35DbHz) {
  std::mt19937 rng(23);
  std::normal_distribution<double> g(0.0, std::sqrt(0.5));
  std::bernoulli_distribution bit(0.5);
  const double s = std::sqrt(std::pow(10.0, 3.5) * 1e-3);
  for (int edge : {0, 7, 19}) {
    BitSynchronizer sync;
    int value = 1;
    int k = 1000;
    for (; k < 6000 && !sync.synchronised(); ++k) {
      if ((k - edge) % 20 == 0) value = bit(rng) ? 1 : -1;
      // a slowly rotating phase: the detector must not need phase lock
      sync.add(
          k, polar(value * s, 0.002 * k) + std::complex<float>(static_cast<float>(g(rng)), static_cast<float>(g(rng))));
    }
    ASSERT_TRUE(sync.synchronised());
    EXPECT_EQ(((sync.edge_period() - edge) % 20 + 20) % 20, 0);
    EXPECT_LT(k - 1000, 2000);
  }
}

// Below ~31 dB-Hz noise flips the 1 ms sign test so often (p = exp(-C/N0 T) / 2 = 0.30 at 27 dB-Hz, 0.36 at 25)
// that the edge bin's count is never 3 times the runner-up's (expected ratio 1 / (2 p) = 1.6 and 1.4): the lead
// test must decide, on the right edge, in about (4 / (1/2 - p))^2 bits plus the runner-up's max-of-19 margin
// (~7-10 s at 27 dB-Hz, ~15-20 s at 25); the bounds are twice that.
TEST(BitSync, LeadTestFindsTheEdgeAt27And25DbHz) {
  std::normal_distribution<double> g(0.0, std::sqrt(0.5));
  std::bernoulli_distribution bit(0.5);
  for (double cn0 : {27.0, 25.0}) {
    const double s = std::sqrt(std::pow(10.0, cn0 / 10.0) * 1e-3);
    int seed = 31;
    for (int edge : {0, 7, 19}) {
      std::mt19937 rng(++seed);
      BitSynchronizer sync;
      int value = 1;
      int k = 1000;
      for (; k < 61000 && !sync.synchronised(); ++k) {
        if ((k - edge) % 20 == 0) value = bit(rng) ? 1 : -1;
        sync.add(k, polar(value * s, 0.002 * k) +
                        std::complex<float>(static_cast<float>(g(rng)), static_cast<float>(g(rng))));
      }
      ASSERT_TRUE(sync.synchronised()) << cn0 << " dB-Hz, edge " << edge;
      EXPECT_EQ(((sync.edge_period() - edge) % 20 + 20) % 20, 0) << cn0 << " dB-Hz, edge " << edge;
      EXPECT_LT(k - 1000, cn0 > 26.0 ? 20000 : 40000) << cn0 << " dB-Hz, edge " << edge;
    }
  }
}

// Noise alone: every bin grows at 1/2 per bit; in 60 s no bin may lead by 4 sigma (a false edge would make the
// channel integrate across bit edges).
TEST(BitSync, NoiseAloneNeverSynchronisesIn60s) {
  std::normal_distribution<double> g(0.0, 1.0);
  for (int seed : {5, 6, 7}) {
    std::mt19937 rng(seed);
    BitSynchronizer sync;
    for (int k = 0; k < 60000; ++k)
      sync.add(k, std::complex<float>(static_cast<float>(g(rng)), static_cast<float>(g(rng))));
    EXPECT_FALSE(sync.synchronised()) << "seed " << seed;
  }
}

namespace {
// 1 ms prompts A d + w (w complex Gaussian, E|w|^2 = 1, A^2 = C/N0 * 1 ms), random +-1 bits starting at `edge`.
struct BitStream {
  std::mt19937 rng;
  std::normal_distribution<double> g{0.0, std::sqrt(0.5)};
  std::bernoulli_distribution bit{0.5};
  double amplitude;
  int edge;
  double cycles_per_ms;  // residual carrier rotation
  int value = 1;
  BitStream(unsigned seed, double cn0_dbhz, int edge_offset, double rotation_cycles_per_ms = 0.0)
      : rng(seed),
        amplitude(std::sqrt(std::pow(10.0, cn0_dbhz / 10.0) * 1e-3)),
        edge(edge_offset),
        cycles_per_ms(rotation_cycles_per_ms) {}
  std::complex<float> prompt(std::int64_t k) {
    if ((k - edge) % 20 == 0) value = bit(rng) ? 1 : -1;
    return polar(value * amplitude, cycles_per_ms * static_cast<double>(k)) +
           std::complex<float>(static_cast<float>(g(rng)), static_cast<float>(g(rng)));
  }
};

double q_function(double x) { return 0.5 * std::erfc(x / std::sqrt(2.0)); }
}  // namespace

// The energy (maximum-likelihood) bit sync against theory: after N bits the argmax of the 20 window energies is
// wrong when some offset m (1..19 ms from the edge) out-scores the edge. Per bit, with S = A^2 and unit noise per
// ms, the difference E_0 - E_m has mean 2 m (20 - m) S and variance (second moments of complex Gaussian quadratic
// forms, the random data, and the m ms that each shifted window shares with the next bit's edge window)
//   V_m = 800 + 16000 S + 40 S ((20-m)^2 + m^2) + 4 S^2 (20-m)^2 m^2 - 2 (20-m)^2 (1 + 40 S) - 2 m^2 (1 + 40 S),
// so P(E_m > E_0) ~ Q(sqrt(N) mean / sqrt(V_m)) (central limit over N bits). The error probability lies between
// the largest of these and their sum (union bound). Measured over 3000 trials of N bits at 25 and 28 dB-Hz.
TEST(BitSync, EnergyTestErrorProbabilityMatchesTheory) {
  struct Case {
    double cn0;
    int bits;
  };
  for (const Case c : {Case{25.0, 16}, Case{28.0, 6}}) {
    const double s = std::pow(10.0, c.cn0 / 10.0) * 1e-3;
    double largest = 0.0, sum = 0.0;
    for (int m = 1; m < 20; ++m) {
      const double a = 20.0 - m;
      const double mean = 2.0 * m * a * s;
      const double v = 800.0 + 16000.0 * s + 40.0 * s * (a * a + m * m) + 4.0 * s * s * a * a * m * m -
                       2.0 * a * a * (1.0 + 40.0 * s) - 2.0 * m * m * (1.0 + 40.0 * s);
      const double p = q_function(std::sqrt(c.bits * 1.0) * mean / std::sqrt(v));
      largest = std::max(largest, p);
      sum += p;
    }
    BitSyncOptions options;
    options.min_energy_bits = 1000;  // never decide: read the argmax after N bits
    options.min_edges = 1000;
    options.min_ratio = 100.0;
    options.min_lead_sigma = 100.0;
    const int trials = 3000;
    int wrong = 0;
    for (int t = 0; t < trials; ++t) {
      const int edge = t % 20;
      BitStream stream(1000u + static_cast<unsigned>(t), c.cn0, edge);
      BitSynchronizer sync(options);
      for (std::int64_t k = 0; sync.energy_bits() < c.bits; ++k) sync.add(k, stream.prompt(k));
      const auto& e = sync.energies();
      const int best = static_cast<int>(std::max_element(e.begin(), e.end()) - e.begin());
      wrong += best != edge;
    }
    const double p = static_cast<double>(wrong) / trials;
    const double sigma = std::sqrt(std::max(sum, 0.01) * (1.0 - std::max(sum, 0.01)) / trials);
    EXPECT_GT(p, largest - 4.0 * sigma) << c.cn0 << " dB-Hz, " << c.bits << " bits";
    EXPECT_LT(p, sum + 4.0 * sigma) << c.cn0 << " dB-Hz, " << c.bits << " bits";
    std::printf("energy bit sync %.0f dB-Hz, %d bits: P(wrong) %.4f, theory [%.4f, %.4f]\n", c.cn0, c.bits, p, largest,
                sum);
  }
}

// The sequential energy test decides on the right edge, and fast: by the moments above the closest offsets
// (m = 1, 19) lead by mean / sqrt(V_1) = 0.45 sigma per bit at 25 dB-Hz and 0.60 at 28, so 5 sigma need
// ~(5 / 0.45)^2 = 123 bits (2.5 s) and 69 bits (1.4 s); at high C/N0 the mid offsets (m = 10: 0 or 400 S per bit
// with random data) lead by at most 1 sigma per bit: 25 bits (0.5 s). The histogram's lead test needs 15-20 s at
// 25 dB-Hz. Checked: no wrong edge in 60 trials each, mean time within 1.6 times the prediction (the variance is
// estimated from the data, and the winner must lead all 19 others), every trial within 4 times it.
TEST(BitSync, EnergyTestDecidesOnTheRightEdgeWithinSeconds) {
  struct Case {
    double cn0;
    double predicted_s;
  };
  BitSyncOptions options;
  options.min_edges = 1000;  // energy test alone
  options.min_ratio = 100.0;
  options.min_lead_sigma = 100.0;
  for (const Case c : {Case{25.0, 2.5}, Case{28.0, 1.4}, Case{40.0, 0.5}}) {
    int wrong = 0;
    double total_s = 0.0, longest_s = 0.0;
    const int trials = 60;
    for (int t = 0; t < trials; ++t) {
      const int edge = (7 * t) % 20;
      BitStream stream(500u + static_cast<unsigned>(t), c.cn0, edge, 0.0005);  // 0.5 Hz left by a PLL
      BitSynchronizer sync(options);
      std::int64_t k = 3;
      for (; k < 30000 && !sync.synchronised(); ++k) sync.add(k, stream.prompt(k));
      wrong += !sync.synchronised() || ((sync.edge_period() - edge) % 20 + 20) % 20 != 0;
      total_s += static_cast<double>(k - 3) * 1e-3;
      longest_s = std::max(longest_s, static_cast<double>(k - 3) * 1e-3);
    }
    const double mean_s = total_s / trials;
    EXPECT_EQ(wrong, 0) << c.cn0 << " dB-Hz";
    EXPECT_LT(mean_s, 1.6 * c.predicted_s) << c.cn0 << " dB-Hz";
    EXPECT_LT(longest_s, 4.0 * c.predicted_s) << c.cn0 << " dB-Hz";
    std::printf("energy bit sync %.0f dB-Hz: decision time mean %.2f s, longest %.2f s (predicted %.1f s)\n", c.cn0,
                mean_s, longest_s, c.predicted_s);
  }
}

// The first-order DLL's code error sampled at the receiver's epochs is an AR(1) sequence: the mean of N samples
// has the variance of N white samples of 1-sigma dll_white_equivalent_sigma_factor times the error's own. Truth:
// the loop closed with dll_rate_correction_chips_per_s on white discriminator noise (20 ms updates, 1 Hz and
// 2 Hz, 0.1 s epochs), 2000 blocks of N = 400 epochs. The variance of the block means has a relative standard
// error sqrt(2 / 2000) = 3.2 %; the large-N form leaves out 2 rho / (N (1 - rho) (1 + rho)) <= 0.6 % here: 10 %.
TEST(DelayLockLoop, WhiteEquivalentSigmaFactorMatchesTheClosedLoopsBlockMeans) {
  for (const double bn : {1.0, 2.0}) {
    const double t = 0.020, interval = 0.1;
    const int per_epoch = 5, n = 400, blocks = 2000;
    std::mt19937_64 rng(41);
    std::normal_distribution<double> noise(0.0, 0.01);  // chips per discriminator reading
    double tau = 0.0, sum_means2 = 0.0, sum_tau2 = 0.0;
    long long count = 0;
    for (int k = 0; k < 200; ++k) tau -= dll_rate_correction_chips_per_s(tau + noise(rng), bn) * t;  // settle
    for (int b = 0; b < blocks; ++b) {
      double sum = 0.0;
      for (int i = 0; i < n; ++i) {
        for (int u = 0; u < per_epoch; ++u) tau -= dll_rate_correction_chips_per_s(tau + noise(rng), bn) * t;
        sum += tau;
        sum_tau2 += tau * tau;
        ++count;
      }
      sum_means2 += (sum / n) * (sum / n);
    }
    const double var_tau = sum_tau2 / count, var_mean = sum_means2 / blocks;
    const double measured = std::sqrt(var_mean * n / var_tau);
    const double factor = dll_white_equivalent_sigma_factor(bn, t, interval);
    std::printf("DLL %.0f Hz: white-equivalent sigma factor closed form %.3f, closed loop %.3f\n", bn, factor,
                measured);
    EXPECT_NEAR(measured / factor, 1.0, 0.10) << bn;
  }
  EXPECT_NEAR(dll_white_equivalent_sigma_factor(1.0, 0.020, 0.1), 2.21, 0.01);  // rho = 0.92^5 = 0.659
  EXPECT_NEAR(dll_white_equivalent_sigma_factor(1.0, 0.020, 10.0), 1.0, 1e-6);  // epochs far apart: white
}

// An order other than 2 or 3 is refused, not rounded to 2 (the tracking options check it at the edge).
TEST(CarrierLoopFilter, OrderOtherThanTwoOrThreeIsRefused) {
  using ultratrack::receiver::CarrierLoopFilter;
  EXPECT_THROW(CarrierLoopFilter(4, 15.0, 0.0, 0.0), std::invalid_argument);
  EXPECT_THROW(CarrierLoopFilter(1, 15.0, 0.0, 0.0), std::invalid_argument);
  CarrierLoopFilter loop(3, 15.0, 0.0, 100.0);
  EXPECT_THROW(loop.set_order(0), std::invalid_argument);
  EXPECT_EQ(loop.order(), 3);
  loop.set_order(2);
  EXPECT_EQ(loop.order(), 2);
  EXPECT_DOUBLE_EQ(loop.frequency_hz(), 100.0);
}

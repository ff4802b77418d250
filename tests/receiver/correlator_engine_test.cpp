// SPDX-License-Identifier: GPL-3.0-or-later
// Correlator engine against closed forms: the carrier's sin/cos, the prompt's Dirichlet loss for a frequency
// error, the code autocorrelation triangle at the early/late offsets, the noise tap, and several antennas.
#include "receiver/correlator_engine.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <random>
#include <stdexcept>
#include <vector>

#include "signals/ca_code.hpp"
#include "signals/gps_constants.hpp"
#include "test_signal.hpp"

using namespace ultratrack;
using namespace ultratrack::receiver;

namespace {
constexpr double kFs = 4e6;

// Periodic autocorrelation of a PRN at an integer lag, normalised (1 at lag 0).
double autocorr(int prn, int lag) {
  const auto& c = signals::ca_code(prn);
  int s = 0;
  for (int k = 0; k < 1023; ++k) s += c[k] * c[((k + lag) % 1023 + 1023) % 1023];
  return s / 1023.0;
}
// Continuous (infinite-bandwidth) correlation of a chip sequence with itself at a fractional offset x chips:
// linear interpolation between the integer-lag values.
double code_correlation(int prn, double x) {
  const double f = std::floor(x);
  const double w = x - f;
  return (1 - w) * autocorr(prn, static_cast<int>(f)) + w * autocorr(prn, static_cast<int>(f) + 1);
}

ReplicaSegment replica_for(const test::TestSatellite& sat, double carrier_hz, double code_offset_chips) {
  ReplicaSegment r;
  const double rate = signals::kCaChipRate_hz * (1.0 + sat.doppler_hz / signals::kL1Frequency_hz);
  r.code_phase_chips = std::fmod(sat.code_phase_chips, 1023.0) + code_offset_chips;
  r.code_step_chips = rate / kFs;
  r.carrier_phase_q32 = 0;
  r.carrier_step_q32 =
      static_cast<std::uint32_t>(static_cast<std::int64_t>(std::llround(carrier_hz / kFs * 4294967296.0)));
  return r;
}
}  // namespace

TEST(CorrelatorEngine, FixedPointSinCosMatchesStdWithinOneMicro) {
  double worst = 0.0;
  for (std::uint64_t p = 0; p < (1ull << 32); p += 4099) {
    float c, s;
    fixed_point_sincos(static_cast<std::uint32_t>(p), &c, &s);
    const double a = 2.0 * M_PI * static_cast<double>(p) / 4294967296.0;
    worst = std::max({worst, std::abs(c - std::cos(a)), std::abs(s - std::sin(a))});
  }
  EXPECT_LT(worst, 1e-6);
}

TEST(CorrelatorEngine, PromptFollowsDirichletLossForFrequencyError) {
  test::TestSatellite sat;
  sat.prn = 5;
  sat.doppler_hz = 1200.0;
  sat.code_phase_chips = 100.25;
  const test::TestSignal sig{kFs, false, 1};
  for (int n : {4000, 3999, 4001, 8000}) {
    const auto x = test::generate({sat}, sig, 0, n);
    for (double df : {0.0, 100.0, 250.0, 500.0, 777.0}) {
      const double offset[] = {0.0};
      CorrelatorEngine engine(5, offset);
      const auto rep = replica_for(sat, sat.doppler_hz + df, 0.0);
      const std::complex<float>* ant[] = {x.data()};
      std::array<TapSums, 1> sums{};
      engine.correlate(ant, n, rep, sums);
      // sum_i exp(-j 2 pi df i / fs), the replica's quantised step included
      const double df_q = static_cast<double>(rep.carrier_step_q32) / 4294967296.0 * kFs - sat.doppler_hz;
      const double x1 = M_PI * df_q / kFs;
      const double mag = std::abs(df_q) < 1e-9 ? n : std::sin(x1 * n) / std::sin(x1);
      const std::complex<double> expected = mag * std::exp(std::complex<double>(0.0, -x1 * (n - 1)));
      EXPECT_LT(std::abs(sums[0][0] - expected), 2e-4 * n) << "df " << df << " n " << n;
    }
  }
}

TEST(CorrelatorEngine, EarlyLateFollowCodeTriangle) {
  test::TestSatellite sat;
  sat.prn = 17;
  sat.doppler_hz = -2300.0;
  sat.code_phase_chips = 511.0;
  const test::TestSignal sig{kFs, false, 1};
  const int n = 4000;
  const auto x = test::generate({sat}, sig, 0, n);
  for (double d : {0.5, 0.1}) {
    const double offsets[] = {1.0, d, 0.0, -d, -1.0};
    CorrelatorEngine engine(17, offsets);
    for (double tau : {0.0, 0.1, 0.25, -0.3, 0.45}) {
      // tau = signal code phase - replica code phase
      const auto rep = replica_for(sat, sat.doppler_hz, -tau);
      const std::complex<float>* ant[] = {x.data()};
      std::array<TapSums, 1> sums{};
      engine.correlate(ant, n, rep, sums);
      for (int t = 0; t < 5; ++t) {
        // The tap reads the replica at (replica phase + offset): its lag behind the signal is tau - offset.
        // Tolerance: at 4000/1023 samples per chip each of the ~512 chip transitions is seen on a sample grid,
        // which moves each transition's share by up to half a sample: about 13 samples RMS over 4000, so 1 %.
        const double expected = n * code_correlation(17, tau - offsets[t]);
        EXPECT_NEAR(sums[0][t].real(), expected, 0.01 * n) << "d " << d << " tau " << tau << " tap " << t;
        EXPECT_NEAR(sums[0][t].imag(), 0.0, 1e-3 * n);
      }
    }
  }
}

TEST(CorrelatorEngine, NoiseTapSeesNoSignal) {
  for (int prn : {1, 7, 19, 32}) {
    const double lag = noise_tap_offset_chips(prn);
    EXPECT_LE(lag, -300);
    EXPECT_GE(lag, -723);
    test::TestSatellite sat;
    sat.prn = prn;
    sat.code_phase_chips = 3.3;
    const auto x = test::generate({sat}, {kFs, false, 1}, 0, 4000);
    for (double tau : {0.0, 0.4, -0.7}) {
      const double offsets[] = {0.0, lag};
      CorrelatorEngine engine(prn, offsets);
      const auto rep = replica_for(sat, 0.0, -tau);
      const std::complex<float>* ant[] = {x.data()};
      std::array<TapSums, 1> sums{};
      engine.correlate(ant, 4000, rep, sums);
      // -1/1023 plus the sampling-grid ripple of the transitions (see the triangle test): below 1 % (-40 dB).
      EXPECT_LT(std::abs(sums[0][1]), 0.01 * 4000) << "PRN " << prn;
      EXPECT_GT(std::abs(sums[0][0]), 0.25 * 4000);
    }
  }
}

TEST(CorrelatorEngine, AntennasShareOneReplica) {
  test::TestSatellite sat;
  sat.prn = 9;
  sat.doppler_hz = 800.0;
  sat.code_phase_chips = 20.0;
  const auto a0 = test::generate({sat}, {kFs, true, 3}, 0, 4000);
  auto shifted = sat;
  shifted.carrier_phase_cycles = 0.3;
  const auto a2 = test::generate({shifted}, {kFs, false, 3}, 0, 4000);
  const double offsets[] = {0.5, 0.0, -0.5};
  CorrelatorEngine engine(9, offsets);
  const auto rep = replica_for(sat, sat.doppler_hz, 0.0);
  const auto clean = test::generate({sat}, {kFs, false, 3}, 0, 4000);
  const std::complex<float>* ant[] = {a0.data(), a0.data(), clean.data(), a2.data()};
  std::array<TapSums, 4> sums{};
  engine.correlate(ant, 4000, rep, sums);
  for (int t = 0; t < 3; ++t) EXPECT_EQ(sums[0][t], sums[1][t]);  // identical antennas: identical outputs
  const double dphi = std::arg(sums[3][1] * std::conj(sums[2][1])) / (2 * M_PI);
  EXPECT_NEAR(dphi, 0.3, 1e-5);
  // and the one-antenna call gives the same numbers as the multi-antenna one
  std::array<TapSums, 1> single{};
  const std::complex<float>* one[] = {a0.data()};
  engine.correlate(one, 4000, rep, single);
  for (int t = 0; t < 3; ++t) EXPECT_EQ(single[0][t], sums[0][t]);
}

TEST(CorrelatorEngine, RejectsBadTapSets) {
  const double none[] = {0.0};
  EXPECT_THROW(CorrelatorEngine(1, std::span<const double>(none, 0)), std::invalid_argument);
  const double too_far[] = {2000.0};
  EXPECT_THROW(CorrelatorEngine(1, too_far), std::invalid_argument);
  EXPECT_THROW(CorrelatorEngine(33, none), std::out_of_range);
}

// The AVX2 and the portable kernels in one process on the same inputs: i8-valued noisy samples with a signal,
// 1..6 taps (the receiver's E/P/L + noise layout among them), 1 and 3 antennas, code steps from 0.2 to 0.99
// chips per sample, start phases in [-1023, 1023), block lengths that are not multiples of 8 or of the 256-sample
// chunk. Same chips by construction, so the sums may differ only by float rounding: per 256-sample chunk of float
// accumulation at most 256 * 2^-24 of the sum of |terms| (1.5e-5), plus the carrier's 3e-6: 2e-5 * sum |x|.
// A single chip read differently would move a sum by 2 |x_k|, ~100x that bound.
TEST(CorrelatorEngine, Avx2AndPortableKernelsAgreeOnTheSameInputs) {
  if (!correlator_avx2_available()) GTEST_SKIP() << "no AVX2+FMA on this CPU: nothing to compare";
  std::mt19937 rng(7);
  std::normal_distribution<float> noise(0.0f, 20.0f);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const std::vector<std::vector<double>> layouts = {{0.0},
                                                    {0.5, 0.0, -0.5},
                                                    {0.5, 0.0, -0.5, noise_tap_offset_chips(9)},
                                                    {1.0, 0.5, 0.0, -0.5, -1.0},
                                                    {0.25, 0.1, 0.0, -0.1, -0.25, -400.0},
                                                    {0.5, 0.0}};
  int compared = 0;
  for (const auto& offsets : layouts) {
    const CorrelatorEngine avx2(9, offsets, CorrelatorIsa::kAvx2), portable(9, offsets, CorrelatorIsa::kBaseline);
    for (int trial = 0; trial < 12; ++trial) {
      const int antennas = trial % 2 == 0 ? 1 : 3;
      const int n = 500 + static_cast<int>(u(rng) * 3500);  // 500..4000 samples
      ReplicaSegment rep;
      rep.code_step_chips = 0.2 + 0.79 * u(rng);
      rep.code_phase_chips = -1023.0 + 2046.0 * u(rng);
      if (rep.code_phase_chips + rep.code_step_chips * n > 2045.0) rep.code_phase_chips -= 1023.0;
      rep.carrier_phase_q32 = static_cast<std::uint32_t>(rng());
      rep.carrier_step_q32 = static_cast<std::uint32_t>(rng()) / 64u;
      std::vector<std::vector<std::complex<float>>> x(static_cast<std::size_t>(antennas));
      std::vector<const std::complex<float>*> ptr;
      double abs_sum = 0.0;
      const auto& chips = signals::ca_code(9);
      for (auto& a : x) {
        a.resize(static_cast<std::size_t>(n));
        for (int i = 0; i < n; ++i) {
          const double chip = rep.code_phase_chips + rep.code_step_chips * i;
          const int c = chips[static_cast<std::size_t>(((static_cast<long>(std::floor(chip)) % 1023) + 1023) % 1023)];
          const float s = 25.0f * static_cast<float>(c);
          a[static_cast<std::size_t>(i)] = {std::round(std::clamp(s + noise(rng), -127.0f, 127.0f)),
                                            std::round(std::clamp(noise(rng), -127.0f, 127.0f))};
          abs_sum += std::abs(a[static_cast<std::size_t>(i)]);
        }
        ptr.push_back(a.data());
      }
      std::vector<TapSums> sa(static_cast<std::size_t>(antennas)), sp(static_cast<std::size_t>(antennas));
      for (auto& s : sa) s.fill({});
      for (auto& s : sp) s.fill({});
      avx2.correlate(ptr, n, rep, sa);
      portable.correlate(ptr, n, rep, sp);
      for (int a = 0; a < antennas; ++a)
        for (int t = 0; t < static_cast<int>(offsets.size()); ++t) {
          EXPECT_LE(std::abs(sa[static_cast<std::size_t>(a)][static_cast<std::size_t>(t)] -
                             sp[static_cast<std::size_t>(a)][static_cast<std::size_t>(t)]),
                    2e-5 * abs_sum / antennas)
              << offsets.size() << " taps, tap " << t << ", antenna " << a << ", trial " << trial;
          ++compared;
        }
    }
  }
  EXPECT_EQ(compared, 12 * 2 * (1 + 3 + 4 + 5 + 6 + 2));  // 6 trials with 1 antenna and 6 with 3 per layout
}

namespace {
struct Planar {
  std::vector<std::int16_t> re, im;
  PlanarI16 view() const { return {re.data(), im.data()}; }
};
Planar to_planar(const std::vector<std::complex<float>>& x, float gain) {
  Planar p{std::vector<std::int16_t>(x.size()), std::vector<std::int16_t>(x.size())};
  convert_to_planar_i16(x.data(), static_cast<int>(x.size()), gain, p.re.data(), p.im.data());
  return p;
}
}  // namespace

// The conversion's definition: round to nearest (ties to even) of x * gain, saturated to int16; odd lengths
// exercise the vector body and the tail.
TEST(CorrelatorEngine, PlanarInt16ConversionRoundsAndSaturates) {
  std::mt19937 rng(3);
  std::normal_distribution<float> g(0.0f, 300.0f);
  std::vector<std::complex<float>> x(1037);
  for (auto& v : x) v = {g(rng), g(rng)};
  x[5] = {1e9f, -1e9f};
  x[6] = {2.5f / 64, -2.5f / 64};  // ties: 2.5 -> 2, -2.5 -> -2
  const Planar p = to_planar(x, 64.0f);
  for (std::size_t i = 0; i < x.size(); ++i) {
    const auto expect = [](float v) {
      return static_cast<std::int16_t>(std::nearbyint(std::clamp(v * 64.0f, -32768.0f, 32767.0f)));
    };
    ASSERT_EQ(p.re[i], expect(x[i].real())) << i;
    ASSERT_EQ(p.im[i], expect(x[i].imag())) << i;
  }
  EXPECT_EQ(p.re[5], 32767);
  EXPECT_EQ(p.im[5], -32768);
  EXPECT_EQ(p.re[6], 2);
  EXPECT_EQ(p.im[6], -2);
}

// The integer kernel against the same closed form as the float kernel (Dirichlet loss of a frequency error),
// on a clean signal of amplitude 1 scaled to 2048 (the receiver's gain puts the noise rms there). Errors: the
// Q15 carrier table (1.5e-5 of amplitude, systematic) and independent roundings of the samples and of the
// wipe-off (< 5e-4 rms per sample, i.e. ~0.03 over 4000 samples): the float test's 2e-4 * n bound holds.
// Loss against the float kernel on the same samples, aligned: below 0.01 dB (the issue allows ~0.1 dB).
TEST(CorrelatorEngine, IntegerKernelFollowsDirichletAndLosesUnder0p01Db) {
  test::TestSatellite sat;
  sat.prn = 5;
  sat.doppler_hz = 1200.0;
  sat.code_phase_chips = 100.25;
  const test::TestSignal sig{kFs, false, 1};
  const float gain = 2048.0f;
  double worst_loss_db = 0.0;
  for (int n : {4000, 3999, 4001, 8000}) {
    const auto x = test::generate({sat}, sig, 0, n);
    const Planar p = to_planar(x, gain);
    for (double df : {0.0, 100.0, 250.0, 500.0, 777.0}) {
      const double offset[] = {0.0};
      CorrelatorEngine engine(5, offset);
      const auto rep = replica_for(sat, sat.doppler_hz + df, 0.0);
      const PlanarI16 ant[] = {p.view()};
      std::array<TapSums, 1> sums{};
      engine.correlate_i16(ant, n, rep, 1.0 / gain, sums);
      const double df_q = static_cast<double>(rep.carrier_step_q32) / 4294967296.0 * kFs - sat.doppler_hz;
      const double x1 = M_PI * df_q / kFs;
      const double mag = std::abs(df_q) < 1e-9 ? n : std::sin(x1 * n) / std::sin(x1);
      const std::complex<double> expected = mag * std::exp(std::complex<double>(0.0, -x1 * (n - 1)));
      EXPECT_LT(std::abs(sums[0][0] - expected), 2e-4 * n) << "df " << df << " n " << n;
      if (df == 0.0) {
        const std::complex<float>* fant[] = {x.data()};
        std::array<TapSums, 1> fsums{};
        engine.correlate(fant, n, rep, fsums);
        worst_loss_db =
            std::max(worst_loss_db, std::abs(20.0 * std::log10(std::abs(sums[0][0]) / std::abs(fsums[0][0]))));
      }
    }
  }
  EXPECT_LT(worst_loss_db, 0.01);
}

// Code taps of the integer kernel follow the autocorrelation triangle as the float kernel's do (same bound).
TEST(CorrelatorEngine, IntegerKernelEarlyLateFollowCodeTriangle) {
  test::TestSatellite sat;
  sat.prn = 17;
  sat.doppler_hz = -2300.0;
  sat.code_phase_chips = 511.0;
  const int n = 4000;
  const auto x = test::generate({sat}, {kFs, false, 1}, 0, n);
  const Planar p = to_planar(x, 2048.0f);
  const double offsets[] = {1.0, 0.5, 0.0, -0.5, -1.0, noise_tap_offset_chips(17)};
  CorrelatorEngine engine(17, offsets);
  for (double tau : {0.0, 0.1, 0.25, -0.3, 0.45}) {
    const auto rep = replica_for(sat, sat.doppler_hz, -tau);
    const PlanarI16 ant[] = {p.view()};
    std::array<TapSums, 1> sums{};
    engine.correlate_i16(ant, n, rep, 1.0 / 2048.0, sums);
    for (int t = 0; t < 5; ++t) {
      EXPECT_NEAR(sums[0][t].real(), n * code_correlation(17, tau - offsets[t]), 0.01 * n)
          << "tau " << tau << " tap " << t;
      EXPECT_NEAR(sums[0][t].imag(), 0.0, 1e-3 * n);
    }
    EXPECT_LT(std::abs(sums[0][5]), 0.01 * n);  // the noise tap
  }
}

// The integer kernel's AVX2 and portable copies: integer sums are exact and the double finish is shared, so
// the results must be bit-identical (any chip read differently, any wrapped int16 would show). Inputs as in the
// float comparison, plus full-scale samples (+-16384 per component: the wipe-off's saturation is exercised).
TEST(CorrelatorEngine, IntegerKernelAvx2AndPortableAreBitIdentical) {
  if (!correlator_avx2_available()) GTEST_SKIP() << "no AVX2+FMA on this CPU: nothing to compare";
  std::mt19937 rng(11);
  std::normal_distribution<float> noise(0.0f, 20.0f);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const std::vector<std::vector<double>> layouts = {{0.0},
                                                    {0.5, 0.0, -0.5},
                                                    {0.5, 0.0, -0.5, noise_tap_offset_chips(9)},
                                                    {1.0, 0.5, 0.0, -0.5, -1.0},
                                                    {0.25, 0.1, 0.0, -0.1, -0.25, -400.0},
                                                    {0.5, 0.0}};
  int compared = 0;
  for (const auto& offsets : layouts) {
    const CorrelatorEngine avx2(9, offsets, CorrelatorIsa::kAvx2), portable(9, offsets, CorrelatorIsa::kBaseline);
    for (int trial = 0; trial < 12; ++trial) {
      const int antennas = trial % 2 == 0 ? 1 : 3;
      const int n = 500 + static_cast<int>(u(rng) * 3500);
      const float gain = trial % 3 == 2 ? 128.0f : 64.0f;  // 128: i8 full scale -> +-16384
      ReplicaSegment rep;
      rep.code_step_chips = trial == 5 ? 0.99 : 0.2 + 0.79 * u(rng);
      rep.code_phase_chips = -1023.0 + 2046.0 * u(rng);
      if (rep.code_phase_chips + rep.code_step_chips * n > 2045.0) rep.code_phase_chips -= 1023.0;
      rep.carrier_phase_q32 = static_cast<std::uint32_t>(rng());
      rep.carrier_step_q32 = static_cast<std::uint32_t>(rng()) / 64u;
      std::vector<Planar> x;
      std::vector<PlanarI16> views;
      const auto& chips = signals::ca_code(9);
      for (int a = 0; a < antennas; ++a) {
        std::vector<std::complex<float>> f(static_cast<std::size_t>(n));
        for (int i = 0; i < n; ++i) {
          const double chip = rep.code_phase_chips + rep.code_step_chips * i;
          const int c = chips[static_cast<std::size_t>(((static_cast<long>(std::floor(chip)) % 1023) + 1023) % 1023)];
          const float s = (gain > 100.0f ? 100.0f : 25.0f) * static_cast<float>(c);
          f[static_cast<std::size_t>(i)] = {std::round(std::clamp(s + noise(rng), -128.0f, 127.0f)),
                                            std::round(std::clamp(noise(rng), -128.0f, 127.0f))};
        }
        x.push_back(to_planar(f, gain));
      }
      for (const auto& p : x) views.push_back(p.view());
      std::vector<TapSums> sa(static_cast<std::size_t>(antennas)), sp(static_cast<std::size_t>(antennas));
      for (auto& s : sa) s.fill({});
      for (auto& s : sp) s.fill({});
      avx2.correlate_i16(views, n, rep, 1.0 / gain, sa);
      portable.correlate_i16(views, n, rep, 1.0 / gain, sp);
      for (int a = 0; a < antennas; ++a)
        for (int t = 0; t < static_cast<int>(offsets.size()); ++t) {
          EXPECT_EQ(sa[static_cast<std::size_t>(a)][static_cast<std::size_t>(t)],
                    sp[static_cast<std::size_t>(a)][static_cast<std::size_t>(t)])
              << offsets.size() << " taps, tap " << t << ", antenna " << a << ", trial " << trial;
          ++compared;
        }
    }
  }
  EXPECT_EQ(compared, 12 * 2 * (1 + 3 + 4 + 5 + 6 + 2));
}

// Every copy of the integer kernel (portable, AVX2, AVX-512) must give bit-identical sums: integer sums are
// exact whatever the lane order or the instruction (pmaddwd + add or vpdpwssd), and the double finish is
// shared. Block lengths around the vector widths and the 1024-sample chunk (1..3001, tails of 1..31), code
// rates of the receiver at 16 / 4 / 2.6 MHz and the 0.99 chip-per-sample limit (and 1.2, the portable
// fallback), carrier steps of either sign, 1 and 3 antennas, 1/3/4/5/6 taps, noise-level and full-scale samples.
TEST(CorrelatorEngine, IntegerKernelEveryCopyIsBitIdenticalToPortable) {
  std::vector<CorrelatorIsa> copies;
  if (correlator_isa_available(CorrelatorIsa::kAvx2)) copies.push_back(CorrelatorIsa::kAvx2);
  if (correlator_isa_available(CorrelatorIsa::kAvx512)) copies.push_back(CorrelatorIsa::kAvx512);
  if (copies.empty()) GTEST_SKIP() << "no vector copy on this CPU: nothing to compare";
  std::mt19937 rng(23);
  std::normal_distribution<float> noise(0.0f, 20.0f);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  // Tap sets whose taps are whole chips apart share chip indices in the vector copies (compiled patterns:
  // E/P/L, P/E/L, E/P/L/noise, prompt/noise, five taps either order); the rest do not share.
  const std::vector<std::vector<double>> layouts = {{0.0},
                                                    {0.5, 0.0, -0.5},
                                                    {0.0, 0.5, -0.5},
                                                    {0.5, 0.0, -0.5, noise_tap_offset_chips(9)},
                                                    {0.0, noise_tap_offset_chips(9)},
                                                    {1.0, 0.5, 0.0, -0.5, -1.0},
                                                    {0.0, 0.5, -0.5, 1.0, -1.0},
                                                    {0.1, 0.0, -0.9},
                                                    {0.25, 0.1, 0.0, -0.1, -0.25, -400.0}};
  const int lengths[] = {1, 7, 31, 32, 33, 100, 1023, 1024, 1025, 1300, 2049, 3001};
  const double steps[] = {1.023e6 / 16e6, 1.023e6 / 4e6, 1.023e6 / 2.6e6, 0.99, 1.2};
  int compared = 0;
  for (const auto& offsets : layouts) {
    const CorrelatorEngine portable(9, offsets, CorrelatorIsa::kBaseline);
    std::vector<CorrelatorEngine> engines;
    for (const auto isa : copies) engines.emplace_back(9, offsets, isa);
    for (int trial = 0; trial < 2 * 12 * 5; ++trial) {
      const int antennas = trial % 2 == 0 ? 1 : 3;
      const int n = lengths[(trial / 2) % 12];
      const float gain = trial % 3 == 2 ? 128.0f : 64.0f;  // 128: i8 full scale -> +-16384 (saturating wipe-off)
      ReplicaSegment rep;
      rep.code_step_chips = steps[(trial / 24) % 5] * (1.0 - 1e-4 * u(rng) * (trial % 5 != 3));
      const double covered = rep.code_step_chips * n;
      rep.code_phase_chips = -1000.0 + u(rng) * std::max(0.0, 3040.0 - covered);  // every tap inside the table
      rep.carrier_phase_q32 = static_cast<std::uint32_t>(rng());
      rep.carrier_step_q32 = static_cast<std::uint32_t>(static_cast<std::int32_t>(rng()) / 256);  // +-2^23: either sign
      std::vector<Planar> x;
      std::vector<PlanarI16> views;
      const auto& chips = signals::ca_code(9);
      for (int a = 0; a < antennas; ++a) {
        std::vector<std::complex<float>> f(static_cast<std::size_t>(n));
        for (int i = 0; i < n; ++i) {
          const double chip = rep.code_phase_chips + rep.code_step_chips * i;
          const int c = chips[static_cast<std::size_t>(((static_cast<long>(std::floor(chip)) % 1023) + 1023) % 1023)];
          const float s = (gain > 100.0f ? 100.0f : 25.0f) * static_cast<float>(c);
          f[static_cast<std::size_t>(i)] = {std::round(std::clamp(s + noise(rng), -128.0f, 127.0f)),
                                            std::round(std::clamp(noise(rng), -128.0f, 127.0f))};
        }
        x.push_back(to_planar(f, gain));
      }
      for (const auto& p : x) views.push_back(p.view());
      std::vector<TapSums> expected(static_cast<std::size_t>(antennas));
      for (auto& s : expected) s.fill({1.0, -2.0});  // sums are added to what is there
      portable.correlate_i16(views, n, rep, 1.0 / gain, expected);
      for (std::size_t e = 0; e < engines.size(); ++e) {
        std::vector<TapSums> got(static_cast<std::size_t>(antennas));
        for (auto& s : got) s.fill({1.0, -2.0});
        engines[e].correlate_i16(views, n, rep, 1.0 / gain, got);
        for (int a = 0; a < antennas; ++a)
          for (int t = 0; t < static_cast<int>(offsets.size()); ++t) {
            ASSERT_EQ(got[static_cast<std::size_t>(a)][static_cast<std::size_t>(t)],
                      expected[static_cast<std::size_t>(a)][static_cast<std::size_t>(t)])
                << "copy " << static_cast<int>(copies[e]) << ", " << offsets.size() << " taps, tap " << t
                << ", antenna " << a << ", n " << n << ", code step " << rep.code_step_chips << ", trial " << trial;
            ++compared;
          }
      }
    }
  }
  EXPECT_EQ(compared, static_cast<int>(copies.size()) * 60 * 4 *
                          (1 + 3 + 3 + 4 + 2 + 5 + 5 + 3 + 6));  // 60 x 1 + 60 x 3 antennas
}

// A level the CPU lacks is refused, never silently replaced; kAuto resolves to an available level.
TEST(CorrelatorEngine, NamedIsaIsHonouredOrRefused) {
  const double offsets[] = {0.0};
  for (const auto isa : {CorrelatorIsa::kBaseline, CorrelatorIsa::kAvx2, CorrelatorIsa::kAvx512}) {
    if (correlator_isa_available(isa))
      EXPECT_NO_THROW(CorrelatorEngine(3, offsets, isa));
    else
      EXPECT_THROW(CorrelatorEngine(3, offsets, isa), std::invalid_argument);
  }
  EXPECT_TRUE(correlator_isa_available(correlator_auto_isa()));
  EXPECT_NE(correlator_auto_isa(), CorrelatorIsa::kAuto);
}

// Several antennas against one replica in the integer kernel: identical antennas give identical sums, and a
// carrier phase offset between antennas is measured exactly (the quantisation is common to both).
TEST(CorrelatorEngine, IntegerKernelAntennasShareOneReplica) {
  test::TestSatellite sat;
  sat.prn = 9;
  sat.doppler_hz = 800.0;
  sat.code_phase_chips = 20.0;
  auto shifted = sat;
  shifted.carrier_phase_cycles = 0.3;
  const auto clean = to_planar(test::generate({sat}, {kFs, false, 3}, 0, 4000), 2048.0f);
  const auto turned = to_planar(test::generate({shifted}, {kFs, false, 3}, 0, 4000), 2048.0f);
  const double offsets[] = {0.5, 0.0, -0.5};
  CorrelatorEngine engine(9, offsets);
  const auto rep = replica_for(sat, sat.doppler_hz, 0.0);
  const PlanarI16 ant[] = {clean.view(), clean.view(), turned.view()};
  std::array<TapSums, 3> sums{};
  engine.correlate_i16(ant, 4000, rep, 1.0 / 2048.0, sums);
  for (int t = 0; t < 3; ++t) EXPECT_EQ(sums[0][t], sums[1][t]);
  // Rounding of 2048-scaled samples: phase noise ~ 5e-4 / sqrt(4000) rad, far below 1e-4 cycles.
  EXPECT_NEAR(std::arg(sums[2][1] * std::conj(sums[0][1])) / (2 * M_PI), 0.3, 1e-4);
}

// Correlator engine against closed forms: the carrier's sin/cos, the prompt's Dirichlet loss for a frequency
// error, the code autocorrelation triangle at the early/late offsets, the noise tap, and several antennas.
#include "receiver/correlator_engine.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <random>
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
  r.carrier_step_q32 = static_cast<std::uint32_t>(static_cast<std::int64_t>(std::llround(carrier_hz / kFs * 4294967296.0)));
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

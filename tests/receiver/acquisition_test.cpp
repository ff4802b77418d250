// SPDX-License-Identifier: GPL-3.0-or-later
// Acquisition against synthetic signals with known truth, the threshold against chi-square tables,
// and the false-alarm rate on pure noise against the binomial law of the requested pfa.
#include "receiver/acquisition.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>

#include "synthetic_ca_signal.hpp"

using namespace ultratrack::receiver;
using ultratrack::test::add_ca_signal;
using ultratrack::test::CaSignal;
using ultratrack::test::complex_noise;

namespace {

// Circular distance between code phases in chips.
double chip_error(double a, double b) {
  double d = std::fmod(a - b, 1023.0);
  if (d > 511.5) d -= 1023.0;
  if (d < -511.5) d += 1023.0;
  return d;
}

}  // namespace

TEST(AcquisitionThreshold, MatchesChiSquareTables) {
  // One cell: Z ~ Gamma(K, 1) = chi2(2K) / 2, so g = chi2 upper quantile / 2 (NIST/SEMATECH table values).
  EXPECT_NEAR(acquisition_threshold(1, 1, 0.01), std::log(100.0), 1e-9);  // exponential tail
  EXPECT_NEAR(acquisition_threshold(2, 1, 0.01), 13.277 / 2.0, 1e-3);     // chi2(4), 0.99
  EXPECT_NEAR(acquisition_threshold(5, 1, 0.05), 18.307 / 2.0, 1e-3);     // chi2(10), 0.95
  EXPECT_NEAR(acquisition_threshold(10, 1, 0.01), 37.566 / 2.0, 1e-3);    // chi2(20), 0.99
  // M cells: per-cell probability 1 - (1 - pfa)^(1/M); K = 1 has the closed form -ln(p_cell).
  const double p_cell = 1.0 - std::pow(1.0 - 1e-3, 1.0 / 68000.0);
  EXPECT_NEAR(acquisition_threshold(1, 68000, 1e-3), -std::log(p_cell), 1e-6);
}

TEST(AcquisitionOptions, RejectsOutOfRangeSettings) {
  AcquisitionOptions o;
  o.fs_hz = 4e6;
  EXPECT_TRUE(o.IsValid(nullptr));
  std::string why;
  auto bad = o;
  bad.coherent_ms = 11;
  EXPECT_FALSE(bad.IsValid(&why));
  EXPECT_FALSE(why.empty());
  bad = o;
  bad.fs_hz = 1e6;
  EXPECT_FALSE(bad.IsValid(nullptr));
  bad = o;
  bad.pfa = 0.0;
  EXPECT_FALSE(bad.IsValid(nullptr));
  bad = o;
  bad.doppler_step_hz = 1500.0;  // coarser than 1 / T_coh
  EXPECT_FALSE(bad.IsValid(nullptr));
  EXPECT_THROW(Acquisition{bad}, std::invalid_argument);
  EXPECT_NEAR(o.step_hz(), 2000.0 / 3.0, 1e-9);
}

struct RateCase {
  double fs_hz;
  double code_phase_chips;
  double doppler_hz;
};

class AcquisitionAtRate : public ::testing::TestWithParam<RateCase> {};

TEST_P(AcquisitionAtRate, FindsSignalAtTrueDopplerAndCodePhase) {
  const RateCase c = GetParam();
  AcquisitionOptions o;
  o.fs_hz = c.fs_hz;
  o.noncoherent = 4;
  o.pfa = 1e-3;
  Acquisition acq(o);
  auto samples = complex_noise(acq.samples_needed(), 7);
  CaSignal s;
  s.prn = 11;
  s.code_phase_chips = c.code_phase_chips;
  s.doppler_hz = c.doppler_hz;
  s.cn0_dbhz = 48.0;
  add_ca_signal(samples, c.fs_hz, s);

  const AcquisitionResult r = acq.search(samples, 11);
  ASSERT_TRUE(r.detected) << "metric " << r.metric << " threshold " << r.threshold;
  // 48 dB-Hz, 4 x 1 ms: Doppler CRLB sqrt(6 / ((2 pi)^2 C/N0 T^3 K)) = 25 Hz; code well under 0.05 chip.
  EXPECT_NEAR(r.doppler_hz, c.doppler_hz, 100.0);
  EXPECT_NEAR(chip_error(r.code_phase_chips, c.code_phase_chips), 0.0, 0.1);
  // Samples to the next epoch, from the truth: (1023 - phase) chips at the Doppler-shifted chip rate.
  const double chip_rate = 1.023e6 * (1.0 + c.doppler_hz / 1575.42e6);
  const double period = 1023.0 * c.fs_hz / chip_rate;
  double expected_samples = std::fmod((1023.0 - c.code_phase_chips) * c.fs_hz / chip_rate, period);
  double sample_error = std::remainder(r.code_phase_samples - expected_samples, period);
  EXPECT_NEAR(sample_error, 0.0, 0.1 * c.fs_hz / 1.023e6);
  // C/N0 from the peak: coherent SNR 63 per block, K = 4 -> about 0.3 dB (1 sigma).
  EXPECT_NEAR(r.cn0_dbhz, 48.0, 1.5);
  EXPECT_GT(r.metric, r.threshold);
}

INSTANTIATE_TEST_SUITE_P(SampleRates, AcquisitionAtRate,
                         ::testing::Values(RateCase{2.6e6, 100.3, -3210.0}, RateCase{4e6, 1012.7, 2480.0},
                                           RateCase{12e6, 0.2, 4321.0}, RateCase{38.192e6, 511.5, -4900.0},
                                           RateCase{16.3676e6, 777.7, 1234.0}));

TEST(Acquisition, TenMsCoherentSurvivesDataBitFlipInsideABlock) {
  AcquisitionOptions o;
  o.fs_hz = 4e6;
  o.coherent_ms = 10;
  o.noncoherent = 2;
  Acquisition acq(o);
  auto samples = complex_noise(acq.samples_needed(), 11);
  CaSignal s;
  s.prn = 5;
  s.code_phase_chips = 333.3;
  s.doppler_hz = -1717.0;
  s.cn0_dbhz = 40.0;
  s.first_bit_edge_s = 0.015;  // a sign flip in the middle of block 2: that block gives nothing coherent
  s.bits = {1, -1};
  add_ca_signal(samples, o.fs_hz, s);
  const auto r = acq.search(samples, 5);
  ASSERT_TRUE(r.detected);
  // One clean 10 ms block at 40 dB-Hz alone would give a Doppler CRLB sqrt(6 / ((2 pi)^2 C/N0 T^3)) = 4 Hz,
  // but the flipped block adds power that grows away from the true Doppler (|1 - exp(j pi df T)|^2 S / 4),
  // which cuts the curvature of the summed peak by 4 (3.29 -> 0.82 S T^2): about 16 Hz (1 sigma). Half a
  // coarse bin (33 Hz) is what tracking pull-in needs.
  EXPECT_NEAR(r.doppler_hz, -1717.0, 33.0);
  EXPECT_NEAR(chip_error(r.code_phase_chips, 333.3), 0.0, 0.1);
}

TEST(Acquisition, NonCoherentSumFollowsCodeDoppler) {
  // 40 x 5 ms = 200 ms at +4.9 kHz: the code drifts by 0.64 chip (2.5 samples), which an unaligned
  // sum would smear across lags. Weak signal (33 dB-Hz) that needs the long sum.
  AcquisitionOptions o;
  o.fs_hz = 4e6;
  o.coherent_ms = 5;
  o.noncoherent = 40;
  o.doppler_max_hz = 5000.0;
  Acquisition acq(o);
  auto samples = complex_noise(acq.samples_needed(), 5);
  CaSignal s;
  s.prn = 30;
  s.code_phase_chips = 12.5;
  s.doppler_hz = 4900.0;
  s.cn0_dbhz = 33.0;
  s.first_bit_edge_s = 0.0;  // edges on block boundaries
  s.bits = {1, -1, -1, 1, 1};
  add_ca_signal(samples, o.fs_hz, s);
  const auto r = acq.search(samples, 30);
  ASSERT_TRUE(r.detected) << r.metric << " " << r.threshold;
  EXPECT_NEAR(r.doppler_hz, 4900.0, 30.0);
  EXPECT_NEAR(chip_error(r.code_phase_chips, 12.5), 0.0, 0.15);
  EXPECT_NEAR(r.cn0_dbhz, 33.0, 1.5);
}

TEST(Acquisition, MultiPrnSearchFindsPresentAndRejectsAbsentSatellites) {
  AcquisitionOptions o;
  o.fs_hz = 4e6;
  o.noncoherent = 5;
  o.pfa = 1e-4;
  Acquisition acq(o);
  auto samples = complex_noise(acq.samples_needed(), 3);
  const std::vector<CaSignal> present{{.prn = 3, .code_phase_chips = 10.0, .doppler_hz = 1000.0, .cn0_dbhz = 46.0},
                                      {.prn = 17, .code_phase_chips = 900.0, .doppler_hz = -4000.0, .cn0_dbhz = 44.0},
                                      {.prn = 24, .code_phase_chips = 456.7, .doppler_hz = 250.0, .cn0_dbhz = 42.0}};
  for (const auto& s : present) add_ca_signal(samples, o.fs_hz, s);
  std::vector<int> prns(32);
  std::iota(prns.begin(), prns.end(), 1);
  const auto results = acq.search(samples, prns);
  ASSERT_EQ(results.size(), 32u);
  for (const auto& r : results) {
    auto it = std::find_if(present.begin(), present.end(), [&](const CaSignal& s) { return s.prn == r.prn; });
    if (it == present.end()) {
      EXPECT_FALSE(r.detected) << "false detection of PRN " << r.prn << " metric " << r.metric;
      continue;
    }
    ASSERT_TRUE(r.detected) << "PRN " << r.prn;
    EXPECT_NEAR(r.doppler_hz, it->doppler_hz, 150.0) << "PRN " << r.prn;
    EXPECT_NEAR(chip_error(r.code_phase_chips, it->code_phase_chips), 0.0, 0.1) << "PRN " << r.prn;
    EXPECT_NEAR(r.cn0_dbhz, it->cn0_dbhz, 1.5) << "PRN " << r.prn;
  }
  // Without cancellation, the shared-spectrum search and single-PRN searches are the same search.
  auto plain_options = o;
  plain_options.cancel_cross_correlation = false;
  Acquisition plain(plain_options);
  const auto shared = plain.search(samples, prns);
  for (int prn : {3, 17, 24, 5}) {
    const auto single = plain.search(samples, prn);
    EXPECT_NEAR(single.metric, shared[static_cast<std::size_t>(prn - 1)].metric, 1e-3 * single.metric);
    EXPECT_DOUBLE_EQ(single.doppler_hz, shared[static_cast<std::size_t>(prn - 1)].doppler_hz);
  }
}

// Strong satellites' Gold-code cross-correlations (-21..-24 dB) add a deterministic term to other PRNs'
// cells that grows with K, so a threshold set for noise alone lets them through: with five satellites at
// 44-50 dB-Hz and K = 10, the absent PRNs gave 59 false alarms in 324 searches (12 trials) without cancellation,
// where 3.2 were expected. Successive cancellation must bring the rate back to pfa (6 trials here).
TEST(Acquisition, CancellationKeepsCrossCorrelationsOfStrongSatellitesOut) {
  AcquisitionOptions o;
  o.fs_hz = 2.046e6;  // 2 samples per chip: cheaper, same cross-correlations
  o.noncoherent = 10;
  o.pfa = 0.01;
  Acquisition acq(o);
  const std::vector<CaSignal> strong{{.prn = 16, .code_phase_chips = 10, .doppler_hz = -2598, .cn0_dbhz = 47},
                                     {.prn = 26, .code_phase_chips = 102, .doppler_hz = -656, .cn0_dbhz = 50},
                                     {.prn = 29, .code_phase_chips = 600, .doppler_hz = 2223, .cn0_dbhz = 47},
                                     {.prn = 31, .code_phase_chips = 726, .doppler_hz = 192, .cn0_dbhz = 50},
                                     {.prn = 32, .code_phase_chips = 315, .doppler_hz = 3383, .cn0_dbhz = 44}};
  std::vector<int> prns(32);
  std::iota(prns.begin(), prns.end(), 1);
  int false_alarms = 0, searches = 0;
  for (int trial = 0; trial < 6; ++trial) {
    auto samples = complex_noise(acq.samples_needed(), 77 + static_cast<unsigned>(trial));
    for (const auto& s : strong) add_ca_signal(samples, o.fs_hz, s);
    for (const auto& r : acq.search(samples, prns)) {
      const bool present = std::any_of(strong.begin(), strong.end(), [&](const CaSignal& s) { return s.prn == r.prn; });
      if (present) {
        EXPECT_TRUE(r.detected) << "PRN " << r.prn << " trial " << trial;
        continue;
      }
      false_alarms += r.detected ? 1 : 0;
      ++searches;
    }
  }
  const double mean = searches * o.pfa, sigma = std::sqrt(searches * o.pfa * (1.0 - o.pfa));
  std::printf("  %d false alarms in %d searches beside strong satellites (expected %.1f +- %.1f)\n", false_alarms,
              searches, mean, sigma);
  EXPECT_LT(false_alarms, mean + 4.0 * sigma);
}

TEST(Acquisition, AssistedWindowSearchesOnlyAroundPrediction) {
  AcquisitionOptions o;
  o.fs_hz = 4e6;
  o.noncoherent = 2;
  Acquisition acq(o);
  auto samples = complex_noise(acq.samples_needed(), 9);
  add_ca_signal(samples, o.fs_hz, {.prn = 8, .code_phase_chips = 600.0, .doppler_hz = 3100.0, .cn0_dbhz = 45.0});
  const auto full = acq.search(samples, 8);
  const auto near = acq.search(samples, 8, DopplerWindow{3000.0, 700.0});
  const auto far = acq.search(samples, 8, DopplerWindow{-3000.0, 700.0});
  ASSERT_TRUE(full.detected);
  ASSERT_TRUE(near.detected);
  EXPECT_LT(near.threshold, full.threshold);  // fewer cells, lower threshold for the same pfa
  EXPECT_NEAR(near.doppler_hz, 3100.0, 150.0);
  EXPECT_NEAR(chip_error(near.code_phase_chips, 600.0), 0.0, 0.1);
  EXPECT_FALSE(far.detected);
}

TEST(Acquisition, ReacquiresOnLaterBlocksWithTheSameEngine) {
  AcquisitionOptions o;
  o.fs_hz = 2.6e6;
  o.noncoherent = 3;
  Acquisition acq(o);
  for (int trial = 0; trial < 3; ++trial) {
    auto samples = complex_noise(acq.samples_needed(), 100 + static_cast<unsigned>(trial));
    const double phase = 100.0 + 300.0 * trial, doppler = -2000.0 + 1500.0 * trial;
    add_ca_signal(samples, o.fs_hz, {.prn = 21, .code_phase_chips = phase, .doppler_hz = doppler, .cn0_dbhz = 46.0});
    const auto r = acq.search(samples, 21);
    ASSERT_TRUE(r.detected);
    EXPECT_NEAR(r.doppler_hz, doppler, 150.0);
    EXPECT_NEAR(chip_error(r.code_phase_chips, phase), 0.0, 0.1);
  }
}

TEST(Acquisition, RejectsBadPrnAndShortInput) {
  AcquisitionOptions o;
  o.fs_hz = 4e6;
  Acquisition acq(o);
  auto samples = complex_noise(acq.samples_needed(), 1);
  EXPECT_THROW(acq.search(samples, 0), std::invalid_argument);
  EXPECT_THROW(acq.search(samples, 33), std::invalid_argument);
  EXPECT_THROW(acq.search(std::span(samples).first(100), 1), std::invalid_argument);
}

// False alarms on pure noise. At 1 sample per chip with a Doppler step of 1/T_coh the cells are
// (nearly) independent, so the detection count over n = trials x 32 PRN searches is Binomial(n, pfa):
// it must fall within mean +- 4 sigma. (Oversampled grids have correlated cells, so their rate is lower.)
class FalseAlarmRate : public ::testing::TestWithParam<int> {};

TEST_P(FalseAlarmRate, MatchesRequestedPfaOnPureNoise) {
  AcquisitionOptions o;
  o.fs_hz = 1.023e6;
  o.noncoherent = GetParam();
  o.doppler_step_hz = 1000.0;
  o.pfa = 0.02;
  Acquisition acq(o);
  std::vector<int> prns(32);
  std::iota(prns.begin(), prns.end(), 1);
  const int trials = 60;
  int detections = 0;
  for (int t = 0; t < trials; ++t) {
    const auto noise = complex_noise(acq.samples_needed(), 1000 + static_cast<unsigned>(t));
    for (const auto& r : acq.search(noise, prns)) detections += r.detected ? 1 : 0;
  }
  const double n = trials * 32.0, mean = n * o.pfa, sigma = std::sqrt(n * o.pfa * (1.0 - o.pfa));
  RecordProperty("detections", detections);
  std::printf("  %d false alarms in %.0f searches (expected %.1f +- %.1f)\n", detections, n, mean, sigma);
  EXPECT_GT(detections, mean - 4.0 * sigma) << "expected " << mean;
  EXPECT_LT(detections, mean + 4.0 * sigma) << "expected " << mean;
}

INSTANTIATE_TEST_SUITE_P(NonCoherentBlocks, FalseAlarmRate, ::testing::Values(1, 4));

TEST(FalseAlarmRate, OversampledGridIsNotAbovePfa) {
  AcquisitionOptions o;
  o.fs_hz = 4e6;
  o.noncoherent = 2;
  o.pfa = 0.02;
  Acquisition acq(o);
  std::vector<int> prns(32);
  std::iota(prns.begin(), prns.end(), 1);
  const int trials = 15;
  int detections = 0;
  for (int t = 0; t < trials; ++t) {
    const auto noise = complex_noise(acq.samples_needed(), 5000 + static_cast<unsigned>(t));
    for (const auto& r : acq.search(noise, prns)) detections += r.detected ? 1 : 0;
  }
  const double n = trials * 32.0, mean = n * o.pfa, sigma = std::sqrt(n * o.pfa * (1.0 - o.pfa));
  std::printf("  %d false alarms in %.0f searches (at most %.1f expected)\n", detections, n, mean);
  EXPECT_LT(detections, mean + 4.0 * sigma) << "expected at most " << mean;
}

// The receiver's search (4 ms x 5 at 2.6 MHz: a grid of 6 steps per FFT bin, so 6 signal spectra per block serve
// all 61 Doppler bins by rotation; the cold start's pool): satellites spread over the whole Doppler range (bins of
// every rotation class, far from their bases) are found at the simulated Doppler and code phase, and every
// result is the same, bit for bit, with 1, 2 and 3 threads (the rows of the cancellation passes are spread
// over the pool).
TEST(Acquisition, RotatedSpectraFindTruthAndPoolDoesNotChangeResults) {
  AcquisitionOptions o;
  o.fs_hz = 2.6e6;
  o.coherent_ms = 4;
  o.noncoherent = 5;
  auto samples = complex_noise(static_cast<std::size_t>(std::llround(o.fs_hz * 0.02)), 11);
  const std::vector<CaSignal> present{{.prn = 5, .code_phase_chips = 100.3, .doppler_hz = -4871.0, .cn0_dbhz = 45.0},
                                      {.prn = 10, .code_phase_chips = 511.8, .doppler_hz = -1234.0, .cn0_dbhz = 42.0},
                                      {.prn = 13, .code_phase_chips = 3.6, .doppler_hz = 77.0, .cn0_dbhz = 45.0},
                                      {.prn = 23, .code_phase_chips = 1001.1, .doppler_hz = 2950.0, .cn0_dbhz = 40.0},
                                      {.prn = 24, .code_phase_chips = 640.5, .doppler_hz = 4420.0, .cn0_dbhz = 45.0}};
  for (const auto& s : present) add_ca_signal(samples, o.fs_hz, s);
  std::vector<int> prns(32);
  std::iota(prns.begin(), prns.end(), 1);
  std::vector<std::vector<AcquisitionResult>> runs;
  for (int threads = 1; threads <= 3; ++threads) {
    WorkerPool pool(threads);
    Acquisition acq(o);
    runs.push_back(acq.search(samples, prns, &pool));
  }
  for (const auto& r : runs[0]) {
    auto it = std::find_if(present.begin(), present.end(), [&](const CaSignal& s) { return s.prn == r.prn; });
    if (it == present.end()) continue;  // false alarms: the pfa tests
    ASSERT_TRUE(r.detected) << "PRN " << r.prn;
    std::printf("  PRN %2d  Doppler error %6.2f Hz  code error %6.3f chips  C/N0 %.1f dB-Hz (true %.1f)\n", r.prn,
                r.doppler_hz - it->doppler_hz, chip_error(r.code_phase_chips, it->code_phase_chips), r.cn0_dbhz,
                it->cn0_dbhz);
    // Fine grid step 166.7 / 8 = 20.8 Hz with a parabola: within half a fine step, plus noise at 40 dB-Hz.
    EXPECT_NEAR(r.doppler_hz, it->doppler_hz, 15.0) << "PRN " << r.prn;
    // Triangle fit on 2.54 samples per chip: a small fraction of a chip.
    EXPECT_NEAR(chip_error(r.code_phase_chips, it->code_phase_chips), 0.0, 0.1) << "PRN " << r.prn;
    EXPECT_NEAR(r.cn0_dbhz, it->cn0_dbhz, 1.5) << "PRN " << r.prn;
  }
  for (std::size_t t = 1; t < runs.size(); ++t)
    for (std::size_t i = 0; i < runs[0].size(); ++i) {
      EXPECT_EQ(runs[t][i].detected, runs[0][i].detected) << t + 1 << " threads, PRN " << i + 1;
      EXPECT_EQ(runs[t][i].doppler_hz, runs[0][i].doppler_hz) << t + 1 << " threads, PRN " << i + 1;
      EXPECT_EQ(runs[t][i].code_phase_chips, runs[0][i].code_phase_chips) << t + 1 << " threads, PRN " << i + 1;
      EXPECT_EQ(runs[t][i].metric, runs[0][i].metric) << t + 1 << " threads, PRN " << i + 1;
    }
}

// SPDX-License-Identifier: GPL-3.0-or-later
// Acquisition of real recordings (../shared/data, skipped when absent) through SampleSource: every
// satellite the data README lists must be found at its Doppler (within one 250 Hz bin of the README's
// grid) and code phase (within half a chip). Extra detections are printed, not failed: the README lists
// what an independent search found, and the strong satellites' Gold-code cross-correlations (-21 to -24 dB)
// can lift an absent PRN over a threshold set for noise alone.
//
// Code phase convention: the README's figure is the delay from the first sample to the next code epoch
// in chips (1023 - our phase, e.g. PRN 16 of the 4 MHz file: 1012.3 there, 10.7 here); ours is the
// phase of the code at the first sample, as the synthetic tests pin down.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numeric>
#include <string>
#include <vector>

#include "receiver/acquisition.hpp"
#include "receiver/sample_source.hpp"
#include "support/test_data.hpp"

using namespace ultratrack::receiver;
using ultratrack::signals::SampleFormat;

namespace {

struct Listed {
  int prn;
  double doppler_hz;
  double readme_delay_chips;
};

struct Recording {
  SampleFormat format;
  SampleSourceOptions source;
  AcquisitionOptions acquisition;
  std::vector<Listed> listed;
  std::vector<int> searched;  // listed PRNs plus any others to search
};

void check_recording(const std::filesystem::path& path, const Recording& rec) {
  SampleSource source(path, rec.format, rec.source);
  Acquisition acquisition(rec.acquisition);
  std::vector<std::complex<float>> samples(acquisition.samples_needed());
  ASSERT_EQ(source.read(samples).count, samples.size());
  const auto results = acquisition.search(samples, rec.searched);
  for (const Listed& l : rec.listed) {
    auto it = std::find_if(results.begin(), results.end(), [&](const AcquisitionResult& r) { return r.prn == l.prn; });
    ASSERT_NE(it, results.end());
    EXPECT_TRUE(it->detected) << "PRN " << l.prn << " metric " << it->metric << " threshold " << it->threshold;
    EXPECT_NEAR(it->doppler_hz, l.doppler_hz, 250.0) << "PRN " << l.prn;
    const double expected_phase = std::fmod(1023.0 - l.readme_delay_chips, 1023.0);
    EXPECT_NEAR(std::remainder(it->code_phase_chips - expected_phase, 1023.0), 0.0, 0.5) << "PRN " << l.prn;
    std::printf(
        "  PRN %2d  doppler %8.1f Hz (README %+.0f)  code phase %8.3f chips (README delay %.1f)  "
        "C/N0 %.1f dB-Hz  metric %.1f / %.2f\n",
        l.prn, it->doppler_hz, l.doppler_hz, it->code_phase_chips, l.readme_delay_chips, it->cn0_dbhz, it->metric,
        it->threshold);
  }
  for (const auto& r : results) {
    const bool listed =
        std::any_of(rec.listed.begin(), rec.listed.end(), [&](const Listed& l) { return l.prn == r.prn; });
    if (r.detected && !listed)
      std::printf("  extra detection: PRN %2d  doppler %8.1f Hz  code phase %8.3f  C/N0 %.1f  metric %.2f / %.2f\n",
                  r.prn, r.doppler_hz, r.code_phase_chips, r.cn0_dbhz, r.metric, r.threshold);
  }
}

std::vector<int> all_prns() {
  std::vector<int> prns(32);
  std::iota(prns.begin(), prns.end(), 1);
  return prns;
}

}  // namespace

TEST(AcquisitionRealData, PocketSdr4MHzComplexTwoBit) {
  ULTRATRACK_REQUIRE_SHARED_FILE(path, "pocketsdr_L1_4MHz_iq_2bit.bin");
  Recording rec;
  rec.format = SampleFormat::i8;
  rec.source.fs_hz = 4e6;
  rec.acquisition.fs_hz = 4e6;
  rec.acquisition.noncoherent = 10;
  rec.listed = {{16, -2500, 1012.3}, {26, -750, 920.4}, {29, 2250, 422.8}, {31, 250, 296.4}, {32, 3500, 707.4}};
  rec.searched = all_prns();
  check_recording(path, rec);
}

TEST(AcquisitionRealData, PocketSdr4MHzWithQNegatedFlipsDopplerSigns) {
  ULTRATRACK_REQUIRE_SHARED_FILE(path, "pocketsdr_L1_4MHz_iq_2bit.bin");
  Recording rec;
  rec.format = SampleFormat::i8;
  rec.source.fs_hz = 4e6;
  rec.source.q_negate = true;
  rec.acquisition.fs_hz = 4e6;
  rec.acquisition.noncoherent = 10;
  // Conjugation flips the Doppler; the code phase is unchanged (the code is real).
  rec.listed = {{16, 2500, 1012.3}, {26, 750, 920.4}, {29, -2250, 422.8}, {31, -250, 296.4}, {32, -3500, 707.4}};
  rec.searched = {16, 26, 29, 31, 32};
  check_recording(path, rec);
}

TEST(AcquisitionRealData, PocketSdr12MHzRealAt3MHzIf) {
  ULTRATRACK_REQUIRE_SHARED_FILE(path, "pocketsdr_L1_12MHz_real_if3MHz.bin");
  Recording rec;
  rec.format = SampleFormat::r8;
  rec.source.fs_hz = 12e6;
  rec.source.if_hz = 3e6;
  rec.acquisition.fs_hz = 12e6;
  rec.acquisition.noncoherent = 10;
  rec.listed = {{2, -2750, 454.2}, {5, 250, 478.3},   {11, -3250, 938.1}, {13, -250, 511.8},
                {15, 1750, 794.3}, {18, 3250, 561.0}, {20, -1250, 696.7}, {30, -2000, 402.3}};
  rec.searched = all_prns();
  check_recording(path, rec);
}

TEST(AcquisitionRealData, Ugsdr38MHzRealAt9p548MHzIf) {
  // Real samples at IF = fs / 4; mixing by -IF (no spectral inversion) gives the README's Doppler signs.
  ULTRATRACK_REQUIRE_SHARED_FILE(path, "ugsdr_L1_38p192MHz_real_if9p55MHz.bin");
  Recording rec;
  rec.format = SampleFormat::r8;
  rec.source.fs_hz = 38.192e6;
  rec.source.if_hz = 9.548e6;
  rec.acquisition.fs_hz = 38.192e6;
  rec.acquisition.noncoherent = 5;
  rec.listed = {{3, 2000, 916.4},  {6, -3750, 755.4}, {9, 2750, 125.8},   {15, 2000, 972.9}, {18, 250, 555.1},
                {21, -500, 359.0}, {22, 1750, 168.4}, {26, -3000, 718.5}, {29, -3250, 862.2}};
  for (const auto& l : rec.listed) rec.searched.push_back(l.prn);  // 38 MHz: listed PRNs only, for speed
  check_recording(path, rec);
}

TEST(AcquisitionRealData, Cttc4MHzFloatWithFrontEndOffset) {
  ULTRATRACK_REQUIRE_SHARED_FILE(path, "gnsssdr_cttc_4MHz_f32_4ms.dat");
  Recording rec;
  rec.format = SampleFormat::f32;
  rec.source.fs_hz = 4e6;
  rec.acquisition.fs_hz = 4e6;
  rec.acquisition.noncoherent = 4;  // the whole 4 ms file
  rec.acquisition.doppler_max_hz = 14000.0;
  rec.listed = {{25, 9000, std::nan("")},
                {29, 9750, std::nan("")},
                {31, 11750, std::nan("")},
                {12, 7250, std::nan("")},
                {2, 8000, std::nan("")}};
  rec.searched = all_prns();
  // The README gives no code phases for this file: check Doppler and detection only.
  SampleSource source(path, rec.format, rec.source);
  Acquisition acquisition(rec.acquisition);
  std::vector<std::complex<float>> samples(acquisition.samples_needed());
  ASSERT_EQ(source.read(samples).count, samples.size());
  const auto results = acquisition.search(samples, rec.searched);
  for (const auto& l : rec.listed) {
    const auto& r = results[static_cast<std::size_t>(l.prn - 1)];
    EXPECT_TRUE(r.detected) << "PRN " << l.prn;
    EXPECT_NEAR(r.doppler_hz, l.doppler_hz, 250.0) << "PRN " << l.prn;
  }
  for (const auto& r : results) {
    const bool listed =
        std::any_of(rec.listed.begin(), rec.listed.end(), [&](const Listed& l) { return l.prn == r.prn; });
    std::printf("  %s PRN %2d  doppler %8.1f Hz  code phase %8.3f  C/N0 %.1f  metric %.2f / %.2f\n",
                listed ? "listed" : (r.detected ? "extra " : "absent"), r.prn, r.doppler_hz, r.code_phase_chips,
                r.cn0_dbhz, r.metric, r.threshold);
  }
}

namespace {

// Code phase change between two acquisitions `span_s` apart must be the code Doppler times the span,
// 1023 * f_d / f_L1 chips per ms. A spectrum taken with the wrong sign (Q negated or the IF side
// inverted) turns the carrier Doppler around but not the code drift, and fails by twice the drift.
void check_code_drift(const std::filesystem::path& path, SampleFormat format, SampleSourceOptions source,
                      const std::vector<int>& prns, double span_s) {
  AcquisitionOptions ao;
  ao.fs_hz = source.fs_hz;
  ao.noncoherent = 5;
  ao.cancel_cross_correlation = false;  // strong satellites only; saves the confirmation searches
  Acquisition acquisition(ao);
  std::vector<std::complex<float>> samples(acquisition.samples_needed());
  SampleSource early(path, format, source);
  ASSERT_EQ(early.read(samples).count, samples.size());
  const auto first = acquisition.search(samples, prns);
  source.start_sample = std::llround(span_s * source.fs_hz);
  SampleSource late(path, format, source);
  ASSERT_EQ(late.read(samples).count, samples.size());
  const auto second = acquisition.search(samples, prns);
  for (std::size_t i = 0; i < prns.size(); ++i) {
    ASSERT_TRUE(first[i].detected && second[i].detected) << "PRN " << prns[i];
    const double drift = std::remainder(second[i].code_phase_chips - first[i].code_phase_chips, 1023.0);
    const double expected = 1.023e6 * first[i].doppler_hz / 1575.42e6 * span_s;
    std::printf("  PRN %2d  Doppler %+7.1f Hz: code drift %+.3f chips in %.3f s, expected %+.3f\n", prns[i],
                first[i].doppler_hz, drift, span_s, expected);
    // Two code-phase estimates at 41-50 dB-Hz: a few hundredths of a chip each.
    EXPECT_NEAR(drift, expected, 0.1) << "PRN " << prns[i];
  }
}

}  // namespace

TEST(AcquisitionRealData, PocketSdr4MHzCodeDriftAgreesWithDopplerOnlyWithQNegated) {
  ULTRATRACK_REQUIRE_SHARED_FILE(path, "pocketsdr_L1_4MHz_iq_2bit.bin");
  SampleSourceOptions source;
  source.fs_hz = 4e6;
  source.q_negate = true;  // PocketSDR's convention; the README's Doppler list takes I + jQ literally
  check_code_drift(path, SampleFormat::i8, source, {16, 29, 32}, 0.45);
}

TEST(AcquisitionRealData, Ugsdr38MHzCodeDriftAgreesWithDopplerWithoutInversion) {
  ULTRATRACK_REQUIRE_SHARED_FILE(path, "ugsdr_L1_38p192MHz_real_if9p55MHz.bin");
  SampleSourceOptions source;
  source.fs_hz = 38.192e6;
  source.if_hz = 9.548e6;
  check_code_drift(path, SampleFormat::r8, source, {6, 9, 29}, 0.09);
}

TEST(AcquisitionRealData, PocketSdr12MHzCodeDriftAgreesWithDopplerWithoutInversion) {
  // Only up to 80 ms: the recording loses about 964 samples (80 us) near 85 ms, after which every PRN's code
  // phase is 82.2 chips further on (measured: 568.66 -> 650.83 chips for PRN 2 between 5 ms blocks 17 and 18).
  ULTRATRACK_REQUIRE_SHARED_FILE(path, "pocketsdr_L1_12MHz_real_if3MHz.bin");
  SampleSourceOptions source;
  source.fs_hz = 12e6;
  source.if_hz = 3e6;
  check_code_drift(path, SampleFormat::r8, source, {2, 11, 18}, 0.075);
}

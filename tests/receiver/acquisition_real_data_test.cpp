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

// SPDX-License-Identifier: GPL-3.0-or-later
// pipelines/truth_lock_rule against closed forms: a satellite whose Doppler ramps at 50 Hz/s has a code phase that
// is the integral of its code rate (written here in closed form, not by the code under test); tracking records
// every 20 ms carry that code phase and Doppler plus known offsets (wrapped into [0, 1023) as a receiver writes
// them), and each satellite breaks one part of the rule at a known time.
#include "pipelines/truth_lock_rule.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <stdexcept>
#include <string>

#include "io/input_error.hpp"
#include "support/test_data.hpp"

namespace ultratrack::pipelines {
namespace {

constexpr double kFs = 1.0e6;  // samples per second
constexpr double kDuration = 10.0;

double doppler_hz(double t) { return 1000.0 + 50.0 * t; }
// Code phase received at t: c0 + 1.023e6 x (t + integral of f_D / f_L1), modulo 1023.
double code_phase_chips(int prn, double t) {
  const double chips = 37.0 * prn + 1.023e6 * (t + (1000.0 * t + 25.0 * t * t) / 1575.42e6);
  return std::fmod(chips, 1023.0);
}

struct Offsets {
  double code_chips = 0.0, frequency_hz = 0.0;
  bool present = true;
};
using Plan = std::function<Offsets(int prn, double t)>;

void write_files(const std::filesystem::path& dir, const Plan& plan) {
  std::ofstream truth(dir / "satellite_truth.csv");
  truth << "sample,t_s,prn,cn0_dbhz,doppler_hz,code_phase_chips\n";
  for (int k = 0; k <= 100; ++k) {
    const double t = 0.1 * k;
    for (int prn = 1; prn <= 7; ++prn) {
      truth << static_cast<long>(std::llround(t * kFs)) << ',' << std::to_string(t) << ',' << prn << ",45.00,"
            << std::to_string(doppler_hz(t)) << ',' << std::to_string(code_phase_chips(prn, t)) << '\n';
    }
    // PRN 9 rises 2 s after the judged span starts: not judged.
    if (t >= 5.0) truth << std::llround(t * kFs) << ',' << t << ",9,45.00,0,0\n";
  }
  std::ofstream tracking(dir / "tracking.csv");
  tracking << "prn,sample,time_s,doppler_hz,code_phase_chips,state\n";
  for (int k = 0; k * 0.02 <= kDuration - 0.02 + 1e-9; ++k) {
    const double t = 0.02 * k;
    for (int prn = 1; prn <= 7; ++prn) {
      const Offsets o = plan(prn, t);
      if (!o.present) continue;
      char line[160];
      std::snprintf(line, sizeof line, "%d,%ld,%.6f,%.4f,%.6f,bit-synced\n", prn, std::lround(t * kFs), t,
                    doppler_hz(t) + o.frequency_hz,
                    std::fmod(code_phase_chips(prn, t) + o.code_chips + 1023.0, 1023.0));
      tracking << line;
    }
  }
}

Offsets plan(int prn, double t) {
  Offsets o{0.3, 2.0, true};  // inside both bounds: the record's code 0.3 chip late, the carrier 2 Hz high
  switch (prn) {
    case 2:
      if (std::abs(t - 6.0) < 1e-9) o.code_chips = -0.6;
      break;  // one record beyond half a chip
    case 3:
      if (t >= 4.0 && t < 5.0) o.frequency_hz = 3.0;
      break;  // a 1 s window 3 Hz off
    case 4:
      o.present = !(t > 7.0 && t < 7.5);
      break;  // a 0.5 s gap after 7.0 s
    case 5:
      o.present = t <= 8.0 + 1e-9;
      break;  // ends 2 s early
    case 6:
      o.present = false;
      break;  // never tracked
    case 7:
      if (t < 2.5) o.code_chips = 5.0;
      break;  // wrong before the judged span only
  }
  return o;
}

TEST(TruthLockRule, EachSatelliteBreaksTheRuleWhereItWasMadeTo) {
  const auto dir = test::scratch_dir();
  write_files(dir, plan);
  TruthLockOptions options;
  options.from_s = 3.0;
  const auto outcomes = truth_lock_outcomes(dir / "satellite_truth.csv", dir / "tracking.csv", options);
  ASSERT_EQ(outcomes.size(), 7u);  // PRN 9 was not transmitted at from_s

  EXPECT_EQ(outcomes[0].outcome, "kept");
  // 0.3 chip back to within the truth's extrapolation over <= 50 ms (< 1e-3 chip); 2 Hz to within the Doppler's
  // linear interpolation (exact for a ramp) and the 4-decimal print.
  EXPECT_NEAR(outcomes[0].max_code_error_chips, 0.3, 1e-3);
  EXPECT_NEAR(outcomes[0].max_frequency_error_hz, 2.0, 1e-3);
  EXPECT_EQ(outcomes[0].records, 350);

  EXPECT_EQ(outcomes[1].outcome, "lost");
  EXPECT_EQ(outcomes[1].reason, "code");
  EXPECT_NEAR(outcomes[1].lost_s, 6.0, 1e-9);

  EXPECT_EQ(outcomes[2].reason, "frequency");
  EXPECT_NEAR(outcomes[2].lost_s, 4.0, 1e-9);

  EXPECT_EQ(outcomes[3].reason, "gap");
  EXPECT_NEAR(outcomes[3].lost_s, 7.0, 1e-9);

  EXPECT_EQ(outcomes[4].reason, "end");
  EXPECT_NEAR(outcomes[4].lost_s, 8.0, 1e-9);

  EXPECT_EQ(outcomes[5].outcome, "not_tracked");
  EXPECT_EQ(outcomes[6].outcome, "kept");  // its wrong records lie before from_s
}

TEST(TruthLockRule, TighterBoundsLoseTheOffsetChannel) {
  const auto dir = test::scratch_dir();
  write_files(dir, plan);
  TruthLockOptions options;
  options.from_s = 3.0;
  options.code_error_chips = 0.25;
  EXPECT_EQ(truth_lock_outcomes(dir / "satellite_truth.csv", dir / "tracking.csv", options)[0].reason, "code");
  options.code_error_chips = 0.5;
  options.frequency_error_hz = 1.5;
  EXPECT_EQ(truth_lock_outcomes(dir / "satellite_truth.csv", dir / "tracking.csv", options)[0].reason, "frequency");
}

TEST(TruthLockRule, OutcomesFileReadsBackAsWritten) {
  const auto dir = test::scratch_dir();
  write_files(dir, plan);
  TruthLockOptions options;
  options.from_s = 3.0;
  const auto outcomes = truth_lock_outcomes(dir / "satellite_truth.csv", dir / "tracking.csv", options);
  write_truth_lock_outcomes_csv(dir / "truth_lock_outcomes.csv", outcomes);
  const auto back = read_truth_lock_outcomes_csv(dir / "truth_lock_outcomes.csv");
  ASSERT_EQ(back.size(), outcomes.size());
  for (std::size_t i = 0; i < back.size(); ++i) {
    EXPECT_EQ(back[i].prn, outcomes[i].prn);
    EXPECT_EQ(back[i].outcome, outcomes[i].outcome);
    EXPECT_EQ(back[i].reason, outcomes[i].reason);
    EXPECT_EQ(std::isnan(back[i].lost_s), std::isnan(outcomes[i].lost_s));
    if (!std::isnan(back[i].lost_s)) EXPECT_NEAR(back[i].lost_s, outcomes[i].lost_s, 5e-4);
    EXPECT_NEAR(back[i].max_code_error_chips, outcomes[i].max_code_error_chips, 5e-5);
    EXPECT_EQ(back[i].records, outcomes[i].records);
  }
  std::ofstream(dir / "bad_outcome.csv")
      << "prn,outcome,reason,lost_s,max_code_error_chips,max_frequency_error_hz,records\n3,maybe,,,0,0,1\n";
  EXPECT_THROW(read_truth_lock_outcomes_csv(dir / "bad_outcome.csv"), io::InputError);
}

TEST(TruthLockRule, BadInputIsNamed) {
  const auto dir = test::scratch_dir();
  write_files(dir, plan);
  TruthLockOptions options;
  options.frequency_error_hz = 0.0;
  EXPECT_THROW(truth_lock_outcomes(dir / "satellite_truth.csv", dir / "tracking.csv", options), std::invalid_argument);

  std::ofstream(dir / "one_row.csv") << "sample,t_s,prn,cn0_dbhz,doppler_hz,code_phase_chips\n0,0,1,45,0,0\n";
  try {
    truth_lock_outcomes(dir / "one_row.csv", dir / "tracking.csv", {});
    FAIL() << "one truth row accepted";
  } catch (const io::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("one_row.csv"), std::string::npos) << e.what();
  }
  std::ofstream(dir / "no_code.csv") << "prn,sample,doppler_hz\n1,0,0\n";
  EXPECT_THROW(truth_lock_outcomes(dir / "satellite_truth.csv", dir / "no_code.csv", {}), io::InputError);
  EXPECT_THROW(truth_lock_outcomes(dir / "satellite_truth.csv", dir / "missing.csv", {}), io::InputError);
}

}  // namespace
}  // namespace ultratrack::pipelines

// SPDX-License-Identifier: GPL-3.0-or-later
// Coarse-time navigation against the IF synthesiser's exact truth: the code phase and Doppler of every
// satellite at sample 0 (signals::IfSynthesiser::visible_satellites, which solves the light time, SV clock,
// ionosphere and the receiver clock its own way), then solve_snapshot with a wrong approximate time.
#include "receiver/snapshot_navigation.hpp"

#include <gtest/gtest.h>

#include <GeographicLib/Geocentric.hpp>
#include <cmath>
#include <memory>
#include <random>

#include "receiver/ionosphere_model.hpp"
#include "signals/if_synthesiser.hpp"
#include "signals/nominal_constellation.hpp"
#include "signals/receiver_motion.hpp"

namespace ultratrack::receiver {
namespace {

Eigen::Vector3d ecef(double lat_deg, double lon_deg, double h_m) {
  double x = 0, y = 0, z = 0;
  GeographicLib::Geocentric::WGS84().Forward(lat_deg, lon_deg, h_m, x, y, z);
  return {x, y, z};
}

struct Truth {
  Eigen::Vector3d r_e_m;
  signals::GpsTime start;
  std::vector<SnapshotMeasurement> measurements;
  signals::KlobucharParameters klobuchar;
};

// Every satellite above 5 deg at sample 0 as the synthesiser transmits it (1 ms clock bias, 0.5 ppm drift).
Truth simulate_truth(const Eigen::Vector3d& r_e_m, const signals::GpsTime& start) {
  const signals::NominalConstellation constellation = signals::nominal_constellation(start);
  signals::SynthesiserOptions o;
  o.sample_rate_hz = 2.6e6;
  o.start = start;
  o.ionosphere = true;
  o.troposphere = true;
  o.klobuchar = constellation.klobuchar;
  o.clock.bias_s = 1.234e-3;
  o.clock.drift_sps = 0.5e-6;
  o.noise = false;
  signals::IfSynthesiser synth(o, constellation.ephemerides,
                               std::make_shared<signals::StaticMotion>(std::vector<Eigen::Vector3d>{r_e_m}));
  Truth t{r_e_m, start, {}, constellation.klobuchar};
  for (const signals::SatelliteView& v : synth.visible_satellites(0)) {
    SnapshotMeasurement m;
    m.prn = v.prn;
    m.code_phase_chips = v.code_phase_chips;
    m.code_sigma_chips = 0.01;
    m.doppler_hz = v.doppler_hz;
    m.doppler_sigma_hz = 1.0;
    m.cn0_dbhz = 45.0;
    for (const auto& e : constellation.ephemerides)
      if (e.prn == v.prn) m.ephemeris = e;
    t.measurements.push_back(m);
  }
  return t;
}

SnapshotOptions options_for(const Truth& t) {
  SnapshotOptions o;
  o.klobuchar = t.klobuchar;
  o.model_sigma_m = 0.5;
  return o;
}

TEST(SnapshotNavigation, ExactMeasurementsGiveTheTruePositionAndTimeFromAWrongTime) {
  const Truth t = simulate_truth(ecef(35.27, 137.01, 100.0), {2190, 518403.0});
  ASSERT_GE(t.measurements.size(), 6u);
  for (const double time_error_s : {-9.5, 0.0, 7.25}) {
    const signals::GpsTime approx = signals::add_seconds(t.start, time_error_s);
    // A-priori position 30 km away.
    const SnapshotSolution s =
        solve_snapshot(t.measurements, approx, t.r_e_m + Eigen::Vector3d(20e3, -15e3, 15e3), options_for(t));
    ASSERT_TRUE(s.valid) << s.failure;
    EXPECT_LT((s.r_e_m - t.r_e_m).norm(), 0.5) << "time error " << time_error_s;
    // The solved time of sample 0 is the true one: the correction undoes the error. The time error is seen only
    // through the satellites' range rates (~500 m/s): 1 cm of model difference between the synthesiser and the
    // solver is 20 us, so 0.1 ms is the tolerance.
    EXPECT_NEAR(s.time_correction_s, -time_error_s, 1e-4);
    EXPECT_EQ(s.quality, "pass");
    EXPECT_TRUE(s.excluded_prns.empty());
  }
}

TEST(SnapshotNavigation, WithoutAnApproximatePositionTheDopplerFixAndGridFindTheTruth) {
  for (const auto& [lat, lon] : {std::pair{35.27, 137.01}, std::pair{-33.9, 18.4}, std::pair{64.1, -21.9}}) {
    const Truth t = simulate_truth(ecef(lat, lon, 300.0), {2190, 540000.0});
    const SnapshotSolution s =
        solve_snapshot(t.measurements, signals::add_seconds(t.start, 4.0), std::nullopt, options_for(t));
    ASSERT_TRUE(s.valid) << s.failure;
    EXPECT_LT((s.r_e_m - t.r_e_m).norm(), 0.5) << lat << " " << lon;
    EXPECT_EQ(s.quality, "pass");
    EXPECT_EQ(s.a_priori, "doppler");
    ASSERT_TRUE(s.doppler_fix_r_e_m.has_value());
    // The Doppler fix of a static receiver: within a few hundred km from exact Doppler.
    EXPECT_LT((*s.doppler_fix_r_e_m - t.r_e_m).norm(), 300e3);
    // Clock drift 0.5 ppm of c, from the Doppler: a fast clock lengthens every pseudorange at c x drift.
    EXPECT_NEAR(s.clock_drift_mps, 0.5e-6 * 299792458.0, 0.5);
  }
}

TEST(SnapshotNavigation, OneFaultyCodePhaseIsExcluded) {
  Truth t = simulate_truth(ecef(35.27, 137.01, 100.0), {2190, 518403.0});
  ASSERT_GE(t.measurements.size(), 7u);
  const int faulty = t.measurements[2].prn;
  t.measurements[2].code_phase_chips = std::fmod(t.measurements[2].code_phase_chips + 1.7, 1023.0);  // ~500 m
  const SnapshotSolution s =
      solve_snapshot(t.measurements, signals::add_seconds(t.start, 3.0), t.r_e_m, options_for(t));
  ASSERT_TRUE(s.valid) << s.failure;
  ASSERT_EQ(s.excluded_prns.size(), 1u);
  EXPECT_EQ(s.excluded_prns.front(), faulty);
  EXPECT_LT((s.r_e_m - t.r_e_m).norm(), 0.5);
  EXPECT_EQ(s.quality, "pass");
}

TEST(SnapshotNavigation, NoisyFaultLeftInFailsTheQualityCheck) {
  Truth t = simulate_truth(ecef(35.27, 137.01, 100.0), {2190, 518403.0});
  SnapshotOptions o = options_for(t);
  o.max_exclusions = 0;
  t.measurements[1].code_phase_chips = std::fmod(t.measurements[1].code_phase_chips + 1.0, 1023.0);  // ~300 m
  const SnapshotSolution s = solve_snapshot(t.measurements, t.start, t.r_e_m, o);
  EXPECT_EQ(s.quality, "fail");
  EXPECT_GT(s.test_statistic, s.test_threshold);
}

TEST(SnapshotNavigation, TooFewSatellitesAndATimeBeyondTheSearchAreFailures) {
  const Truth t = simulate_truth(ecef(35.27, 137.01, 100.0), {2190, 518403.0});
  std::vector<SnapshotMeasurement> four(t.measurements.begin(), t.measurements.begin() + 4);
  const SnapshotSolution few = solve_snapshot(four, t.start, t.r_e_m, options_for(t));
  EXPECT_FALSE(few.valid);
  EXPECT_NE(few.failure.find("fewer than 5"), std::string::npos) << few.failure;

  SnapshotOptions o = options_for(t);
  o.time_sigma_s = 2.0;  // a search of +-6 s; the time is 20 s off
  const SnapshotSolution late = solve_snapshot(t.measurements, signals::add_seconds(t.start, 20.0), t.r_e_m, o);
  EXPECT_FALSE(late.valid);
  EXPECT_NE(late.failure.find("beyond the search"), std::string::npos) << late.failure;
}

TEST(SnapshotNavigation, CodeNoiseGivesErrorsOfTheSizeTheSigmasSay) {
  const Truth exact = simulate_truth(ecef(48.1, 11.6, 500.0), {2190, 560000.0});
  std::mt19937_64 rng(5);
  std::normal_distribution<double> unit;
  int inside = 0, runs = 40;
  for (int run = 0; run < runs; ++run) {
    Truth t = exact;
    for (auto& m : t.measurements) {
      m.code_sigma_chips = 0.02;  // 5.9 m
      m.code_phase_chips = std::fmod(m.code_phase_chips + 0.02 * unit(rng) + 1023.0, 1023.0);
    }
    SnapshotOptions o = options_for(t);
    const SnapshotSolution s = solve_snapshot(t.measurements, signals::add_seconds(t.start, -2.0), t.r_e_m, o);
    ASSERT_TRUE(s.valid) << s.failure;
    // Up error within 2 sigma about 95 % of the time.
    double lat = 0, lon = 0, h = 0;
    GeographicLib::Geocentric::WGS84().Reverse(exact.r_e_m.x(), exact.r_e_m.y(), exact.r_e_m.z(), lat, lon, h);
    inside += std::fabs(s.height_m - h) < 2.0 * s.sigma_enu_m.z();
  }
  EXPECT_GE(inside, 33) << "of " << runs;
}

}  // namespace
}  // namespace ultratrack::receiver

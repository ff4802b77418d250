// SPDX-License-Identifier: GPL-3.0-or-later
// Satellite position/velocity/clock (IS-GPS-200 Table 20-IV) against a published worked example, finite
// differences of the position and clock, the Kepler-orbit closed forms and the Sagnac closed form.
#include "signals/satellite_state.hpp"

#include <gtest/gtest.h>

#include <GeographicLib/Geocentric.hpp>
#include <cmath>

#include "signals/gps_constants.hpp"
#include "signals/rinex_nav.hpp"
#include "support/test_data.hpp"

using namespace ultratrack::signals;

namespace {

// The example ephemeris of szymon2024/gps-labs (gps_lab02/GpsSatPos.hs, an IS-GPS-200N implementation in
// Haskell), whose printed result for (week 2304, tow 424830) is
//   X = 22151566.575334515, Y = 13275548.286060918, Z = 7260529.645377433 m.
// That example has no clock terms and omega/Omega/M0 already in radians.
Ephemeris worked_example() {
  Ephemeris e;
  e.prn = 1;
  e.week = 2304;
  e.crs_m = 134.75;
  e.delta_n_radps = 4.12374319903e-9;
  e.m0_rad = -2.23037324521;
  e.cuc_rad = 7.25500285625e-6;
  e.e = 1.61300709005e-2;
  e.cus_rad = 8.00378620625e-6;
  e.sqrt_a_sqrtm = 5153.71900558;
  e.toe_s = 424800.0;
  e.toc_s = 424800.0;
  e.cic_rad = 7.07805156708e-8;
  e.omega0_rad = -2.84371723002;
  e.cis_rad = 2.6635825634e-7;
  e.i0_rad = 0.967821256634;
  e.crc_m = 226.75;
  e.omega_rad = -1.2251476939;
  e.omega_dot_radps = -7.73246494535e-9;
  e.idot_radps = 2.60367988229e-10;
  e.af0_s = 1.2e-4;
  e.af1_sps = -3.4e-12;
  e.af2_sps2 = 1.0e-19;
  e.tgd_s = -1.1e-8;
  return e;
}

// Eccentric anomaly by bisection on f(E) = E - e sin E - M (monotonic): independent of the Newton solver.
double eccentric_anomaly_by_bisection(double M, double e) {
  double lo = M - 1.0, hi = M + 1.0;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (mid - e * std::sin(mid) - M > 0.0 ? hi : lo) = mid;
  }
  return 0.5 * (lo + hi);
}

double mean_anomaly(const Ephemeris& e, const GpsTime& t) {
  const double A = e.sqrt_a_sqrtm * e.sqrt_a_sqrtm;
  return e.m0_rad + (std::sqrt(kGM_m3ps2 / (A * A * A)) + e.delta_n_radps) * seconds_between(t, e.toe());
}

void expect_velocity_matches_central_difference(const Ephemeris& eph, const GpsTime& t) {
  // Central difference with h = 1 s: truncation h^2/6 |d3r/dt3| ~ |v| n^2 / 6 ~ 2e-5 m/s; rounding of
  // 2.6e7 m positions ~ 4e-9 m / 2 s. Tolerance 1e-4 m/s.
  const double h = 1.0;
  const SatelliteState s = satellite_state(eph, t);
  const Eigen::Vector3d fd =
      (satellite_state(eph, add_seconds(t, h)).r_e_m - satellite_state(eph, add_seconds(t, -h)).r_e_m) / (2 * h);
  EXPECT_LT((s.v_e_mps - fd).norm(), 1e-4) << "PRN " << eph.prn << " at tow " << t.tow_s;
  EXPECT_GT(s.v_e_mps.norm(), 2500.0);  // ECEF speed of a GPS satellite is ~2.6-3.9 km/s
  EXPECT_LT(s.v_e_mps.norm(), 4500.0);
}

}  // namespace

TEST(SatelliteState, MatchesPublishedWorkedExample) {
  const SatelliteState s = satellite_state(worked_example(), {2304, 424830.0});
  // Same algorithm and constants: agreement to the Kepler tolerance (1e-12 rad * 2.6e7 m ~ 3e-5 m).
  EXPECT_NEAR(s.r_e_m.x(), 22151566.575334515, 1e-3);
  EXPECT_NEAR(s.r_e_m.y(), 13275548.286060918, 1e-3);
  EXPECT_NEAR(s.r_e_m.z(), 7260529.645377433, 1e-3);
}

TEST(SatelliteState, VelocityMatchesCentralDifferenceOfPosition) {
  const Ephemeris eph = worked_example();
  for (double dt : {-7200.0, -1000.0, 0.0, 30.0, 3600.0, 7200.0})
    expect_velocity_matches_central_difference(eph, add_seconds(eph.toe(), dt));
}

TEST(SatelliteState, RadiusAndRelativisticTermFollowKeplerOrbit) {
  const Ephemeris eph = worked_example();
  const double A = eph.sqrt_a_sqrtm * eph.sqrt_a_sqrtm;
  for (double dt = -7200.0; dt <= 7200.0; dt += 900.0) {
    const GpsTime t = add_seconds(eph.toe(), dt);
    const SatelliteState s = satellite_state(eph, t);
    const double E = eccentric_anomaly_by_bisection(mean_anomaly(eph, t), eph.e);
    // |r| = A(1 - e cos E) + dr, with |dr| <= sqrt(Crs^2 + Crc^2).
    EXPECT_LE(std::abs(s.r_e_m.norm() - A * (1.0 - eph.e * std::cos(E))), std::hypot(eph.crs_m, eph.crc_m) + 1e-3);
    EXPECT_NEAR(s.relativistic_s, kRelativisticF_spsqrtm * eph.e * eph.sqrt_a_sqrtm * std::sin(E), 1e-17);
    EXPECT_LE(std::abs(s.relativistic_s), std::abs(kRelativisticF_spsqrtm) * eph.e * eph.sqrt_a_sqrtm);
    EXPECT_DOUBLE_EQ(s.tgd_s, eph.tgd_s);
  }
}

TEST(SatelliteState, ClockDriftMatchesCentralDifferenceOfBias) {
  const Ephemeris eph = worked_example();
  for (double dt : {-5000.0, 0.0, 4000.0}) {
    const GpsTime t = add_seconds(eph.toe(), dt);
    const double h = 1.0;
    const double fd =
        (satellite_state(eph, add_seconds(t, h)).clock_bias_s - satellite_state(eph, add_seconds(t, -h)).clock_bias_s) /
        (2 * h);
    // Second derivative of the bias ~ F e sqrt(A) n^2 ~ 5e-16 s/s^2: truncation ~1e-16; rounding of
    // 1e-4 s biases ~ 1e-20 s. Tolerance 1e-15 s/s against a drift of ~3e-12 s/s.
    EXPECT_NEAR(satellite_state(eph, t).clock_drift_sps, fd, 1e-15);
  }
}

TEST(SatelliteState, ClockPolynomialAndTgd) {
  const Ephemeris eph = worked_example();
  const GpsTime t = add_seconds(eph.toc(), 1000.0);
  const SatelliteState s = satellite_state(eph, t);
  const double poly = eph.af0_s + eph.af1_sps * 1000.0 + eph.af2_sps2 * 1e6;
  EXPECT_NEAR(s.clock_bias_s - s.relativistic_s, poly, 1e-18);
  EXPECT_NEAR(l1_ca_clock_correction_s(eph, t), s.clock_bias_s - eph.tgd_s, 1e-18);
}

TEST(SatelliteState, TimeFromEphemerisIsWrappedAcrossTheWeek) {
  // toe late in week W; t early in week W+1 given with the next week number: t_k = +1000 s either way.
  Ephemeris eph = worked_example();
  eph.toe_s = eph.toc_s = 604000.0;
  const SatelliteState a = satellite_state(eph, {eph.week + 1, 200.0});
  const SatelliteState b = satellite_state(eph, {eph.week, 605000.0});
  EXPECT_LT((a.r_e_m - b.r_e_m).norm(), 1e-6);
  EXPECT_NEAR(a.clock_bias_s, b.clock_bias_s, 1e-18);
}

TEST(SatelliteState, RotationToReceiveFrameIsEarthRotationAboutZ) {
  const Eigen::Vector3d r(2.0e7, 0.0, 1.0e7);
  const double tau = 0.075;
  const Eigen::Vector3d q = rotate_to_receive_frame(r, tau);
  EXPECT_NEAR(q.norm(), r.norm(), 1e-6);
  EXPECT_DOUBLE_EQ(q.z(), r.z());
  // The earth turns east during the flight, so a point fixed at transmit appears west (negative y).
  EXPECT_NEAR(q.y(), -r.x() * std::sin(kEarthRotationRate_radps * tau), 1e-6);
}

TEST(SatelliteState, SagnacCorrectionMatchesClosedForm) {
  const GeographicLib::Geocentric& wgs = GeographicLib::Geocentric::WGS84();
  Eigen::Vector3d rx;
  wgs.Forward(35.274016, 137.013759, 100.0, rx.x(), rx.y(), rx.z());
  const Ephemeris eph = worked_example();
  double max_abs = 0.0;
  for (double dt = 0.0; dt < 43200.0; dt += 600.0) {
    const Eigen::Vector3d sat = satellite_state(eph, add_seconds(eph.toe(), dt)).r_e_m;
    const double range = geometric_range_m(sat, rx);
    // Closed form to first order in omega_e*tau: (omega_e / c)(x_s y_r - y_s x_r). The neglected second
    // order is ~ |r_s| (omega_e tau)^2 / 2 ~ 4e-4 m.
    const double sagnac = kEarthRotationRate_radps / kSpeedOfLight_mps * (sat.x() * rx.y() - sat.y() * rx.x());
    EXPECT_NEAR(range - (sat - rx).norm(), sagnac, 2e-3);
    // The travel time is self-consistent.
    EXPECT_NEAR((rotate_to_receive_frame(sat, range / kSpeedOfLight_mps) - rx).norm(), range, 1e-6);
    max_abs = std::max(max_abs, std::abs(sagnac));
  }
  // Order of tens of metres for a mid-latitude user (bound: omega_e/c |r_s| |r_r| cos(lat) ~ 33 m).
  EXPECT_GT(max_abs, 5.0);
  EXPECT_LT(max_abs, 40.0);
}

TEST(SatelliteState, BrdcSatellitesFollowKeplerOrbitAndFiniteDifferences) {
  const RinexNavData nav = read_rinex_nav(ultratrack::test::shipped_nav_file());
  ASSERT_FALSE(nav.ephemerides.empty());
  for (const Ephemeris& eph : nav.ephemerides) {
    const double A = eph.sqrt_a_sqrtm * eph.sqrt_a_sqrtm;
    for (double dt : {-7200.0, 0.0, 7200.0}) {
      const GpsTime t = add_seconds(eph.toe(), dt);
      const SatelliteState s = satellite_state(eph, t);
      const double E = eccentric_anomaly_by_bisection(mean_anomaly(eph, t), eph.e);
      EXPECT_LE(std::abs(s.r_e_m.norm() - A * (1.0 - eph.e * std::cos(E))), std::hypot(eph.crs_m, eph.crc_m) + 1e-3);
      // Within A(1 -+ e) (plus the harmonic radius correction) and, for GPS (A ~ 26560 km, e < 0.025;
      // this file has e up to 0.0219), within 25,800-27,300 km.
      EXPECT_GT(s.r_e_m.norm(), A * (1.0 - eph.e) - std::hypot(eph.crs_m, eph.crc_m));
      EXPECT_LT(s.r_e_m.norm(), A * (1.0 + eph.e) + std::hypot(eph.crs_m, eph.crc_m));
      EXPECT_GT(s.r_e_m.norm(), 25800e3);
      EXPECT_LT(s.r_e_m.norm(), 27300e3);
      EXPECT_LE(std::abs(s.relativistic_s), std::abs(kRelativisticF_spsqrtm) * eph.e * eph.sqrt_a_sqrtm);
    }
    expect_velocity_matches_central_difference(eph, add_seconds(eph.toe(), 1234.0));
  }
}

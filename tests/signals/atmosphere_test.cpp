// SPDX-License-Identifier: GPL-3.0-or-later
// Klobuchar and troposphere against closed forms of IS-GPS-200 20.3.3.5.2.5 (night-time floor, the
// 14:00 peak, the period and amplitude floors) and the Saastamoinen/standard-atmosphere magnitudes.
// (The daytime model is also checked against gps-sdr-sim's printed delays in sky_brdc_test.cpp.)
#include "signals/atmosphere.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "io/units.hpp"
#include "signals/gps_constants.hpp"

using namespace ultratrack::signals;

namespace {

// The broadcast parameters of the shipped tests/data/brdc3540_0000-0200.14n (ION ALPHA / ION BETA of its header).
KlobucharParameters brdc3540_params() {
  KlobucharParameters k;
  const double a[4] = {0.2887e-07, 0.2235e-07, -0.1192e-06, 0.5960e-07};
  const double b[4] = {0.1536e+06, -0.1966e+06, -0.6554e+05, 0.3932e+06};
  for (int i = 0; i < 4; ++i) {
    k.alpha[i] = a[i];
    k.beta[i] = b[i];
  }
  k.valid = true;
  return k;
}

double obliquity(double elevation_rad) { return 1.0 + 16.0 * std::pow(0.53 - elevation_rad / kPi, 3); }

}  // namespace

TEST(Klobuchar, NightTimeIsFiveNanosecondsTimesObliquity) {
  const KlobucharParameters k = brdc3540_params();
  // Receiver at longitude 0: local time = GPS time of day (plus a few minutes for the pierce point).
  // At 02:00 the phase |x| is far beyond 1.57 for any period >= 72000 s.
  for (double el_deg : {5.0, 15.0, 30.0, 60.0, 90.0}) {
    for (double az_deg : {0.0, 90.0, 200.0}) {
      const double d = klobuchar_delay_s(k, 45.0 * ultratrack::io::kRadPerDeg, 0.0, az_deg * ultratrack::io::kRadPerDeg,
                                         el_deg * ultratrack::io::kRadPerDeg, 2.0 * 3600.0);
      EXPECT_NEAR(d, 5e-9 * obliquity(el_deg * ultratrack::io::kRadPerDeg), 1e-15) << el_deg << " " << az_deg;
    }
  }
  // Obliquity factor: 1 at the zenith (to 4e-4), about 3 at 5 degrees.
  EXPECT_NEAR(obliquity(M_PI / 2), 1.000432, 1e-6);
}

TEST(Klobuchar, PeakAtFourteenHoursLocalIsFloorPlusAlpha0AtGeomagneticEquator) {
  // Choose geometry so that the pierce point has geomagnetic latitude 0 (phi_i = 0 and
  // lambda_i = 1.617 - 0.5 semicircles) and local time 50400 s: then delay = F (5 ns + alpha_0).
  const KlobucharParameters k = brdc3540_params();
  const double el = 0.5 * kPi;  // zenith: psi = 0.0137/0.61 - 0.022 semicircles
  const double psi = 0.0137 / (0.5 + 0.11) - 0.022;
  const double az = 0.5 * kPi;  // due east: phi_i = phi_u, lambda_i = lambda_u + psi
  const double lambda_i = 1.617 - 0.5;
  const double lon = (lambda_i - psi) * kPi;
  const double tow = 50400.0 - 43200.0 * lambda_i + 86400.0;  // so that 43200 lambda_i + tow = 50400 (mod day)
  const double d = klobuchar_delay_s(k, 0.0, lon, az, el, tow);
  EXPECT_NEAR(d, obliquity(el) * (5e-9 + k.alpha[0]), 1e-15);
}

TEST(Klobuchar, PeriodAndAmplitudeFloors) {
  KlobucharParameters k;
  k.alpha[0] = 20e-9;
  k.valid = true;  // betas all zero: period floored to 72000 s
  const double psi = 0.0137 / 0.61 - 0.022;
  const double lambda_i = 1.117;
  const double lon = (lambda_i - psi) * kPi;
  const double dt = 7200.0;  // two hours after the peak: x = 2 pi 7200 / 72000
  const double tow = 50400.0 + dt - 43200.0 * lambda_i + 86400.0;
  const double x = 2.0 * kPi * dt / 72000.0;
  const double expected = obliquity(0.5 * kPi) * (5e-9 + 20e-9 * (1 - x * x / 2 + x * x * x * x / 24));
  EXPECT_NEAR(klobuchar_delay_s(k, 0.0, lon, 0.5 * kPi, 0.5 * kPi, tow), expected, 1e-15);
  // A negative amplitude polynomial is floored at zero: only the 5 ns floor remains, even at the peak.
  k.alpha[0] = -20e-9;
  EXPECT_NEAR(klobuchar_delay_s(k, 0.0, lon, 0.5 * kPi, 0.5 * kPi, 50400.0 - 43200.0 * lambda_i + 86400.0),
              obliquity(0.5 * kPi) * 5e-9, 1e-15);
  // Invalid parameters: no model.
  k.valid = false;
  EXPECT_EQ(klobuchar_delay_s(k, 0.0, lon, 0.5 * kPi, 0.5 * kPi, 50400.0), 0.0);
}

TEST(Troposphere, ZenithDelayAtSeaLevelIsAboutTwoPointThreeToTwoPointFourMetres) {
  // Hydrostatic part at 45 deg latitude with 1013.25 hPa: 0.0022768 * 1013.25 = 2.307 m; the wet part of a
  // standard atmosphere at 15 C and 50 % humidity adds ~0.09 m.
  const double z = troposphere_delay_m(45.0 * ultratrack::io::kRadPerDeg, 0.0, 90.0 * ultratrack::io::kRadPerDeg);
  EXPECT_GT(z, 2.30);
  EXPECT_LT(z, 2.45);
  // Higher receivers see less: the scale height of the dry delay is ~8 km.
  const double z1000 =
      troposphere_delay_m(45.0 * ultratrack::io::kRadPerDeg, 1000.0, 90.0 * ultratrack::io::kRadPerDeg);
  EXPECT_NEAR(z1000 / z, std::exp(-1000.0 / 8400.0), 0.02);
  EXPECT_LT(troposphere_delay_m(45.0 * ultratrack::io::kRadPerDeg, 10000.0, 90.0 * ultratrack::io::kRadPerDeg),
            0.35 * z);
  EXPECT_GE(troposphere_delay_m(45.0 * ultratrack::io::kRadPerDeg, 50000.0, 90.0 * ultratrack::io::kRadPerDeg), 0.0);
}

TEST(Troposphere, MappingFollowsOneOverSinElevationAboveFifteenDegrees) {
  const double zenith =
      troposphere_delay_m(35.0 * ultratrack::io::kRadPerDeg, 100.0, 90.0 * ultratrack::io::kRadPerDeg);
  for (double el_deg = 15.0; el_deg <= 90.0; el_deg += 5.0) {
    const double ratio =
        troposphere_delay_m(35.0 * ultratrack::io::kRadPerDeg, 100.0, el_deg * ultratrack::io::kRadPerDeg) / zenith;
    // The curvature term changes the flat-earth 1/sin(el) by less than 2 % above 15 deg.
    EXPECT_NEAR(ratio * std::sin(el_deg * ultratrack::io::kRadPerDeg), 1.0, 0.02) << el_deg;
  }
  // Near the horizon the spherical atmosphere keeps the mapping below 1/sin(el) and finite.
  const double m5 =
      troposphere_delay_m(35.0 * ultratrack::io::kRadPerDeg, 100.0, 5.0 * ultratrack::io::kRadPerDeg) / zenith;
  EXPECT_LT(m5, 1.0 / std::sin(5.0 * ultratrack::io::kRadPerDeg));
  EXPECT_GT(m5, 9.5);
  EXPECT_TRUE(std::isfinite(troposphere_delay_m(35.0 * ultratrack::io::kRadPerDeg, 100.0, 0.0)));
}

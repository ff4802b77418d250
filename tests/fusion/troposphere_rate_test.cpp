// SPDX-License-Identifier: GPL-3.0-or-later
// The troposphere's rate in the predicted pseudorange rate (fusion/tight_measurements): against the numerical
// derivative of the same troposphere model along the true geometry, i.e. prepare_satellites (satellite from its
// ephemeris at its own transmit time, elevation from the antenna) at t - 0.5 s and t + 0.5 s for an antenna moving
// at 500 km/h and climbing 10 m/s. The implementation differentiates analytically (line of sight and vertical
// turning, height rate); the truth here moves the satellite along its orbit and the antenna along its path.
#include <gtest/gtest.h>

#include <GeographicLib/Geocentric.hpp>
#include <cmath>

#include "fusion/tight_measurements.hpp"
#include "signals/gps_constants.hpp"
#include "signals/nominal_constellation.hpp"

namespace ultratrack::fusion {
namespace {

constexpr double kC = signals::kSpeedOfLight_mps;

std::vector<SatelliteObservable> satellites_at(const std::vector<signals::Ephemeris>& eph, const signals::GpsTime& t,
                                               const Eigen::Vector3d& r_ant, bool troposphere) {
  receiver::ObservationEpoch epoch;
  epoch.receive_time = t;
  for (const auto& e : eph) {
    receiver::Observation o;
    o.prn = e.prn;
    o.pseudorange_m = 0.075 * kC;  // transmit time to ~10 ms: the satellite moves < 40 m (no effect on the slopes)
    o.doppler_hz = 0.0;
    epoch.observations.push_back(o);
  }
  TightOptions opt;
  opt.elevation_mask_rad = 5.0 * M_PI / 180.0;
  opt.ionosphere = false;
  opt.troposphere = troposphere;
  return prepare_satellites(epoch, eph, signals::KlobucharParameters{}, r_ant, opt);
}

const SatelliteObservable* find(const std::vector<SatelliteObservable>& v, int prn) {
  for (const auto& s : v)
    if (s.prn == prn) return &s;
  return nullptr;
}

TEST(TroposphereRate, MatchesTheNumericalDerivativeOfTheModelForMovingSatelliteAndAntenna) {
  const signals::GpsTime t{2300, 200000.0};
  const std::vector<signals::Ephemeris> eph = signals::nominal_constellation(t).ephemerides;
  const auto& wgs = GeographicLib::Geocentric::WGS84();
  const double lat = 35.27, lon = 137.01, h = 100.0;
  double x, y, z;
  wgs.Forward(lat, lon, h, x, y, z);
  const Eigen::Vector3d r0(x, y, z);
  // 500 km/h to the north-east and 10 m/s up (a climbing turn's speeds), ECEF.
  const double la = lat * M_PI / 180.0, lo = lon * M_PI / 180.0;
  const Eigen::Vector3d north(-std::sin(la) * std::cos(lo), -std::sin(la) * std::sin(lo), std::cos(la));
  const Eigen::Vector3d east(-std::sin(lo), std::cos(lo), 0.0);
  const Eigen::Vector3d up(std::cos(la) * std::cos(lo), std::cos(la) * std::sin(lo), std::sin(la));
  const Eigen::Vector3d v_ant = 138.9 / std::sqrt(2.0) * (north + east) + 10.0 * up;
  const Eigen::Vector3d v_still = Eigen::Vector3d::Zero();

  const auto now = satellites_at(eph, t, r0, true);
  ASSERT_GE(now.size(), 5u);
  constexpr double kDt = 0.5;
  int low = 0;
  for (const SatelliteObservable& s : now) {
    for (const Eigen::Vector3d& v : {v_still, v_ant}) {
      const auto before = satellites_at(eph, signals::add_seconds(t, -kDt), r0 - v * kDt, true);
      const auto after = satellites_at(eph, signals::add_seconds(t, kDt), r0 + v * kDt, true);
      const SatelliteObservable *a = find(before, s.prn), *b = find(after, s.prn);
      ASSERT_TRUE(a && b) << s.prn;
      const double numerical = (b->atmosphere_m - a->atmosphere_m) / (2.0 * kDt);
      const double analytic = troposphere_rate_mps(s, r0, v);
      // Central difference error ~ kDt^2 / 6 x third derivative (< 1e-6 m/s here); the analytic vertical's turn on
      // a sphere against the ellipsoid's normal: < 0.5 % of the antenna's share. 1 % + 2 um/s.
      EXPECT_NEAR(analytic, numerical, 0.01 * std::abs(numerical) + 2e-6)
          << "PRN " << s.prn << " elevation " << s.elevation_rad * 180.0 / M_PI << " deg, moving " << v.norm();
      // And it is in the predicted range rate: with the troposphere on minus off.
      const auto dry_all = satellites_at(eph, t, r0, false);
      const SatelliteObservable* dry = find(dry_all, s.prn);
      ASSERT_TRUE(dry);
      EXPECT_NEAR(predicted_range_rate_mps(s, r0, v, 0.0) - predicted_range_rate_mps(*dry, r0, v, 0.0), analytic, 1e-9);
      if (s.elevation_rad < 20.0 * M_PI / 180.0 && std::abs(numerical) > 2e-3) ++low;
    }
  }
  EXPECT_GE(low, 1) << "no low satellite with a rate of mm/s: the check would be empty";
}

}  // namespace
}  // namespace ultratrack::fusion

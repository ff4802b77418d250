// SPDX-License-Identifier: GPL-3.0-or-later
// The built-in constellation: its broadcast ephemerides, put through the IS-GPS-200 orbit algorithm,
// give the SPS Performance Standard slot geometry (planes 60 deg apart at 55 deg, slot RAAN and argument
// of latitude at the 1993-07-01 defined epoch), and are valid, healthy and deterministic.
#include "signals/nominal_constellation.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <GeographicLib/Geocentric.hpp>
#include <cmath>
#include <set>

#include "signals/ephemeris_selection.hpp"
#include "signals/gps_constants.hpp"
#include "signals/look_angles.hpp"
#include "signals/satellite_state.hpp"

using namespace ultratrack::signals;

namespace {

constexpr double kRad2Deg = 180.0 / M_PI;

struct Elements {
  double inclination_deg, node_lon_ecef_deg, arg_lat_deg, radius_m;
};

// Geometric elements from ECEF position and velocity. The broadcast model turns the orbit plane at
// OMEGA_DOT in inertial space, so the velocity is taken in the frame that turns with the node
// (omega_e - OMEGA_DOT relative to ECEF), where the plane is fixed.
Elements elements(const SatelliteState& s, double omega_dot_radps) {
  const Eigen::Vector3d w(0, 0, kEarthRotationRate_radps - omega_dot_radps);
  const Eigen::Vector3d v_node = s.v_e_mps + w.cross(s.r_e_m);
  const Eigen::Vector3d h = s.r_e_m.cross(v_node);
  const Eigen::Vector3d node = Eigen::Vector3d::UnitZ().cross(h).normalized();
  Elements e;
  e.inclination_deg = std::acos(h.z() / h.norm()) * kRad2Deg;
  e.node_lon_ecef_deg = std::atan2(node.y(), node.x()) * kRad2Deg;
  const double cos_u = node.dot(s.r_e_m) / s.r_e_m.norm();
  const double sin_u = h.normalized().dot(node.cross(s.r_e_m)) / s.r_e_m.norm();
  e.arg_lat_deg = std::atan2(sin_u, cos_u) * kRad2Deg;
  e.radius_m = s.r_e_m.norm();
  return e;
}

double wrap180(double a) { return std::remainder(a, 360.0); }

}  // namespace

TEST(NominalConstellation, ValidHealthyEphemeridesNearTheRequestedTime) {
  const GpsTime t{2190, 518400.0 + 1234.5};
  const NominalConstellation c = nominal_constellation(t);
  ASSERT_EQ(c.ephemerides.size(), 24u);
  ASSERT_EQ(c.slots.size(), 24u);
  std::set<int> prns;
  for (const Ephemeris& e : c.ephemerides) {
    prns.insert(e.prn);
    EXPECT_EQ(e.health, 0);
    EXPECT_EQ(e.iodc & 0xff, e.iode);
    EXPECT_LT(e.iode, 240);
    EXPECT_LE(std::abs(seconds_between(t, e.toe())), 3600.0);
    EXPECT_EQ(std::fmod(e.toe_s, 16.0), 0.0);  // toe is broadcast in units of 16 s
    EXPECT_LT(std::abs(e.af0_s), 1e-3);
    EXPECT_LT(std::abs(e.af1_sps), 1e-10);
    EXPECT_LT(std::abs(e.tgd_s), 1e-8);
    EXPECT_NEAR(e.sqrt_a_sqrtm * e.sqrt_a_sqrtm, 26559.7e3, 1e-3);
    EXPECT_LT(e.e, 0.02);
    EXPECT_TRUE(select_ephemeris(c.ephemerides, e.prn, t).has_value());
  }
  EXPECT_EQ(prns.size(), 24u);
  EXPECT_TRUE(c.klobuchar.valid);
  EXPECT_TRUE(c.utc.valid);
  EXPECT_EQ(c.utc.delta_t_ls_s, 18);
  // Deterministic.
  const NominalConstellation again = nominal_constellation(t);
  for (size_t i = 0; i < 24; ++i) {
    EXPECT_EQ(again.ephemerides[i].m0_rad, c.ephemerides[i].m0_rad);
    EXPECT_EQ(again.ephemerides[i].omega0_rad, c.ephemerides[i].omega0_rad);
  }
}

TEST(NominalConstellation, SixPlanesSixtyDegreesApartAtFiftyFiveDegrees) {
  const GpsTime t{2190, 518400.0};
  const NominalConstellation c = nominal_constellation(t);
  for (size_t i = 0; i < 24; ++i) {
    const Elements el = elements(satellite_state(c.ephemerides[i], t), c.ephemerides[i].omega_dot_radps);
    EXPECT_NEAR(el.inclination_deg, 55.0, 1e-6);
    EXPECT_NEAR(el.radius_m, 26559.7e3, c.ephemerides[i].e * 26559.7e3 + 1e-3);  // A (1 -+ e)
    // Plane k (A..F) has its node 60 deg east of plane A's.
    const Elements a = elements(satellite_state(c.ephemerides[0], t), c.ephemerides[0].omega_dot_radps);
    const int plane = static_cast<int>(i) / 4;
    EXPECT_NEAR(wrap180(el.node_lon_ecef_deg - a.node_lon_ecef_deg - 60.0 * plane), 0.0, 1e-6) << c.slots[i];
  }
}

TEST(NominalConstellation, SlotsMatchTheSpsPerformanceStandardTableAtItsEpoch) {
  // At the defined epoch 1993-07-01 00:00 UTC (GPST 00:00:09; GHA 18h36m14.4s) each satellite is at its
  // slot's RAAN and argument of latitude (SPS PS 2001 Table 3-1; a few published values).
  const GpsTime epoch = gps_time_from_utc({1993, 7, 1, 0, 0, 0.0}, 9);
  const NominalConstellation c = nominal_constellation(epoch);
  const double gha_deg = (18.0 + 36.0 / 60.0 + 14.4 / 3600.0) * 15.0;
  const struct {
    int index;
    double raan_deg, arg_lat_deg;
  } slots[] = {{0, 272.847, 268.126}, {5, 332.847, 173.336},  {10, 32.847, 339.666},
               {12, 92.847, 135.226}, {19, 152.847, 333.686}, {23, 212.847, 135.346}};
  for (const auto& s : slots) {
    const Elements el =
        elements(satellite_state(c.ephemerides[s.index], epoch), c.ephemerides[s.index].omega_dot_radps);
    // The slot's argument of latitude is the mean one (M + omega); the true one from geometry differs
    // by the equation of the centre, at most 2e rad.
    const double e = c.ephemerides[s.index].e;
    EXPECT_NEAR(wrap180(el.node_lon_ecef_deg + gha_deg - s.raan_deg), 0.0, 1e-6) << c.slots[s.index];
    EXPECT_NEAR(wrap180(el.arg_lat_deg - s.arg_lat_deg), 0.0, 2.0 * e * kRad2Deg + 1e-6) << c.slots[s.index];
  }
}

TEST(NominalConstellation, EarthFixedGeometryRepeatsAndGivesAUsableSky) {
  // Any receiver sees 4 or more satellites above 10 deg (the design goal of the 24-slot constellation
  // is four or more everywhere, always); at a mid-latitude site typically 6-10.
  Eigen::Vector3d rx;
  GeographicLib::Geocentric::WGS84().Forward(35.274016, 137.013759, 100.0, rx.x(), rx.y(), rx.z());
  for (double hours = 0.0; hours < 24.0; hours += 1.5) {
    const GpsTime t = add_seconds({2190, 518400.0}, hours * 3600.0);
    const NominalConstellation c = nominal_constellation(t);
    int visible = 0;
    for (const Ephemeris& e : c.ephemerides)
      if (look_angles(rx, satellite_state(e, t).r_e_m).elevation_rad > 10.0 / kRad2Deg) ++visible;
    EXPECT_GE(visible, 4) << hours;
    EXPECT_LE(visible, 12) << hours;
  }
  // The same earth-fixed positions one repeat period (2 pi / (omega_e - OMEGA_DOT)) later, whichever
  // toe each set gets: a check of the week-independent propagation.
  const double repeat_s = 2.0 * kPi / (kEarthRotationRate_radps + 4.4874e-7 * kPi / 180.0);
  const GpsTime t0{2190, 518400.0 + 100.0};
  const GpsTime t1 = add_seconds(t0, 7.0 * repeat_s);
  const NominalConstellation c0 = nominal_constellation(t0), c1 = nominal_constellation(t1);
  for (size_t i = 0; i < 24; ++i)
    EXPECT_LT((satellite_state(c0.ephemerides[i], t0).r_e_m - satellite_state(c1.ephemerides[i], t1).r_e_m).norm(), 1.0)
        << c0.slots[i];
}

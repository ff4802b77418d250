// SPDX-License-Identifier: GPL-3.0-or-later
// Sky geometry from broadcast ephemerides cross-checked with what gps-sdr-sim (an independent simulator) printed
// for the same file: the shipped brdc3540_0000-0200.14n (tests/data); and the sky over the seed scenario's receiver
// listed for the record.
#include <gtest/gtest.h>

#include <GeographicLib/Geocentric.hpp>
#include <cmath>
#include <cstdio>
#include <map>
#include <vector>

#include "signals/atmosphere.hpp"
#include "signals/ephemeris_selection.hpp"
#include "signals/gps_constants.hpp"
#include "signals/look_angles.hpp"
#include "signals/rinex_nav.hpp"
#include "signals/satellite_state.hpp"
#include "support/test_data.hpp"

using namespace ultratrack::signals;

namespace {

constexpr double kRad2Deg = 180.0 / M_PI;

struct Seen {
  int prn;
  double az_deg, el_deg, range_m, iono_m;
};

Eigen::Vector3d ecef(double lat_deg, double lon_deg, double h_m) {
  Eigen::Vector3d r;
  GeographicLib::Geocentric::WGS84().Forward(lat_deg, lon_deg, h_m, r.x(), r.y(), r.z());
  return r;
}

// Satellites above `mask_deg` for a static receiver at receive time t: light time iterated, position
// rotated into the receive-time frame, look angles from it.
std::vector<Seen> sky(const RinexNavData& nav, double lat_deg, double lon_deg, double h_m, const GpsTime& t,
                      double mask_deg, bool include_unhealthy) {
  const Eigen::Vector3d rx = ecef(lat_deg, lon_deg, h_m);
  std::vector<Seen> out;
  for (int prn = kMinPrn; prn <= kMaxPrn; ++prn) {
    const auto eph = select_ephemeris(nav.ephemerides, prn, t, {include_unhealthy});
    if (!eph) continue;
    double tau = 0.075;
    Eigen::Vector3d sat_rx_frame;
    for (int i = 0; i < 4; ++i) {
      const Eigen::Vector3d sat = satellite_state(*eph, add_seconds(t, -tau)).r_e_m;
      tau = geometric_range_m(sat, rx) / kSpeedOfLight_mps;
      sat_rx_frame = rotate_to_receive_frame(sat, tau);
    }
    const LookAngles la = look_angles(rx, sat_rx_frame);
    if (la.elevation_rad * kRad2Deg <= mask_deg) continue;
    const double iono_m = kSpeedOfLight_mps * klobuchar_delay_s(nav.klobuchar, lat_deg / kRad2Deg, lon_deg / kRad2Deg,
                                                                la.azimuth_rad, la.elevation_rad, t.tow_s);
    out.push_back({prn, la.azimuth_rad * kRad2Deg, la.elevation_rad * kRad2Deg, tau * kSpeedOfLight_mps, iono_m});
  }
  return out;
}

void expect_matches_printout(const std::vector<Seen>& ours, const std::map<int, Seen>& printed, bool check_iono) {
  ASSERT_EQ(ours.size(), printed.size());
  for (const Seen& s : ours) {
    ASSERT_TRUE(printed.count(s.prn)) << "PRN " << s.prn << " not in gps-sdr-sim's list";
    const Seen& p = printed.at(s.prn);
    // Printed to 0.1 deg / 0.1 m: half a unit of rounding plus a margin for gps-sdr-sim's first-order
    // light-time extrapolation (millimetres).
    EXPECT_NEAR(s.az_deg, p.az_deg, 0.06) << "PRN " << s.prn;
    EXPECT_NEAR(s.el_deg, p.el_deg, 0.06) << "PRN " << s.prn;
    EXPECT_NEAR(s.range_m, p.range_m, 0.06) << "PRN " << s.prn;
    if (check_iono) {
      EXPECT_NEAR(s.iono_m, p.iono_m, 0.06) << "PRN " << s.prn;
    }
  }
}

}  // namespace

// gps-sdr-sim on brdc3540.14n (the day the shipped file is cut from), user motion circle.csv of its repository,
// start 2014/12/20,00:00:00 (1823:518400), ionosphere on: the list it prints at the start, for the first point of
// circle.csv (ECEF -3813477.954, 3554276.552, 3662785.237 m, Nagoya), as published in a public README of a
// HackRF test set-up (its command line names brdc0970.22n, but the start time it printed is this file's first
// epoch). Every satellite above the horizon, the unhealthy PRN 8 included, were it up (gps-sdr-sim ignores health).
TEST(SkyBrdc, ShippedFileMatchesGpsSdrSimAtCircleStart) {
  const RinexNavData nav = read_rinex_nav(ultratrack::test::shipped_nav_file());
  const std::map<int, Seen> printed = {
      {1, {1, 75.5, 19.0, 23842014.1, 17.4}},    {2, {2, 278.2, 8.6, 25211959.5, 16.6}},
      {3, {3, 44.8, 38.2, 22161310.3, 11.1}},    {6, {6, 298.1, 43.4, 21779609.4, 9.6}},
      {9, {9, 144.3, 29.1, 22867978.9, 13.9}},   {10, {10, 222.8, 34.6, 22165342.9, 11.6}},
      {11, {11, 98.7, 7.0, 25049095.4, 24.3}},   {12, {12, 326.9, 5.0, 25187588.2, 16.5}},
      {17, {17, 350.8, 83.8, 20316661.5, 7.3}},  {20, {20, 47.2, 49.4, 21274204.2, 9.3}},
      {23, {23, 106.0, 35.7, 22595053.5, 12.2}}, {28, {28, 201.9, 27.9, 22755566.1, 13.5}},
      {32, {32, 43.1, 2.2, 25691385.0, 25.0}}};
  double lat_deg = 0, lon_deg = 0, h_m = 0;
  GeographicLib::Geocentric::WGS84().Reverse(-3813477.954, 3554276.552, 3662785.237, lat_deg, lon_deg, h_m);
  const GpsTime t{ultratrack::test::shipped_nav_week, ultratrack::test::shipped_nav_tow_s};
  expect_matches_printout(sky(nav, lat_deg, lon_deg, h_m, t, 0.0, true), printed, true);
}

// The shipped file over the seed scenario's receiver (Nagoya) at its first epoch, for the tests that simulate it:
// the healthy satellites above 10 deg: gps-sdr-sim's list above (printed 100 m away) cut at 10 deg. PRN 8, the
// file's unhealthy satellite, is below the horizon there.
TEST(SkyBrdc, ShippedFileSatellitesAboveTenDegreesAtNagoya) {
  const RinexNavData nav = read_rinex_nav(ultratrack::test::shipped_nav_file());
  const GpsTime t{ultratrack::test::shipped_nav_week, ultratrack::test::shipped_nav_tow_s};
  const auto healthy = sky(nav, 35.274016, 137.013759, 100.0, t, 10.0, false);
  std::printf(
      "brdc3540_0000-0200.14n, 2014-12-20 00:00:00 GPST, receiver 35.274016 N 137.013759 E 100 m, el > 10 deg:\n");
  std::vector<int> prns;
  for (const Seen& s : healthy) {
    std::printf("  PRN %02d  az %6.1f deg  el %5.1f deg  range %11.1f m  iono %4.1f m\n", s.prn, s.az_deg, s.el_deg,
                s.range_m, s.iono_m);
    prns.push_back(s.prn);
  }
  EXPECT_EQ(prns, (std::vector<int>{1, 3, 6, 9, 10, 17, 20, 23, 28}));
  EXPECT_EQ(healthy.size(), sky(nav, 35.274016, 137.013759, 100.0, t, 10.0, true).size());
}

// SPDX-License-Identifier: GPL-3.0-or-later
// Ephemeris selection: health, IODE/IODC consistency, fit interval and nearest toe, on the shipped
// brdc3540_0000-0200.14n (PRN 8 unhealthy, 01:59:44 sets), on brdc0010.22n's known cases (PRN 14/18 IODC, PRN 28
// unhealthy; shared data) and on hand-made sets for the rules.
#include "signals/ephemeris_selection.hpp"

#include <gtest/gtest.h>

#include "signals/rinex_nav.hpp"
#include "support/test_data.hpp"

using namespace ultratrack::signals;

namespace {

Ephemeris make(int prn, int week, double toe_s, int iode) {
  Ephemeris e;
  e.prn = prn;
  e.week = week;
  e.toe_s = e.toc_s = toe_s;
  e.iode = iode;
  e.iodc = iode;
  e.sqrt_a_sqrtm = 5153.7;
  return e;
}

}  // namespace

TEST(EphemerisSelection, IodeMustEqualLowEightBitsOfIodc) {
  Ephemeris e = make(1, 2190, 0.0, 23);
  e.iodc = 535;  // 0b10'0001'0111: low 8 bits 23
  EXPECT_TRUE(iode_matches_iodc(e));
  e.iodc = 24;
  EXPECT_FALSE(iode_matches_iodc(e));
  EXPECT_FALSE(select_ephemeris({e}, 1, e.toe()).has_value());
}

TEST(EphemerisSelection, FitIntervalIsCentredOnToe) {
  const Ephemeris e = make(3, 2190, 518400.0, 10);
  EXPECT_TRUE(within_fit_interval(e, add_seconds(e.toe(), 7200.0)));
  EXPECT_TRUE(within_fit_interval(e, add_seconds(e.toe(), -7200.0)));
  EXPECT_FALSE(within_fit_interval(e, add_seconds(e.toe(), 7201.0)));
  EXPECT_FALSE(within_fit_interval(e, add_seconds(e.toe(), -7201.0)));
  Ephemeris six = e;  // fit flag 1 with an ordinary IODC: 6 hours
  six.fit_interval_flag = 1;
  EXPECT_TRUE(within_fit_interval(six, add_seconds(six.toe(), 10800.0)));
  EXPECT_FALSE(within_fit_interval(six, add_seconds(six.toe(), 10801.0)));
  Ephemeris eight = six;  // IODC 240-247: 8 hours
  eight.iodc = eight.iode = 242;
  EXPECT_TRUE(within_fit_interval(eight, add_seconds(eight.toe(), 14400.0)));
  EXPECT_FALSE(within_fit_interval(eight, add_seconds(eight.toe(), 14401.0)));
  // Across the week boundary.
  const Ephemeris late = make(3, 2190, 601200.0, 11);
  EXPECT_TRUE(within_fit_interval(late, {2191, 3600.0}));
  EXPECT_FALSE(select_ephemeris({late}, 3, {2191, 7300.0}).has_value());
  EXPECT_TRUE(select_ephemeris({late}, 3, {2191, 3600.0}).has_value());
}

TEST(EphemerisSelection, NearestToeWinsAndTiesPreferThePastThenTheLaterEntry) {
  const Ephemeris a = make(7, 2190, 518400.0, 1);
  const Ephemeris b = make(7, 2190, 525600.0, 2);
  const std::vector<Ephemeris> sets = {a, b, make(8, 2190, 518400.0, 3)};
  EXPECT_EQ(select_ephemeris(sets, 7, {2190, 518400.0 + 3500.0})->iode, 1);
  EXPECT_EQ(select_ephemeris(sets, 7, {2190, 518400.0 + 3700.0})->iode, 2);
  EXPECT_EQ(select_ephemeris(sets, 7, {2190, 518400.0 + 3600.0})->iode, 1);  // tie: toe not in the future
  EXPECT_EQ(select_ephemeris(sets, 8, {2190, 518400.0})->iode, 3);
  EXPECT_FALSE(select_ephemeris(sets, 9, {2190, 518400.0}).has_value());
  // Same toe, new upload (different IODE): the later entry wins, whichever order the toes tie in.
  const Ephemeris a2 = make(7, 2190, 518400.0, 77);
  EXPECT_EQ(select_ephemeris({a, a2}, 7, {2190, 518400.0})->iode, 77);
}

TEST(EphemerisSelection, UnhealthyOnlyWhenAsked) {
  Ephemeris e = make(4, 2190, 518400.0, 5);
  e.health = 63;
  EXPECT_FALSE(select_ephemeris({e}, 4, e.toe()).has_value());
  EXPECT_TRUE(select_ephemeris({e}, 4, e.toe(), {.include_unhealthy = true}).has_value());
}

TEST(EphemerisSelection, Brdc0010KnownCases) {
  ULTRATRACK_REQUIRE_SHARED_FILE(path, "brdc0010.22n");
  const RinexNavData nav = read_rinex_nav(path);
  const GpsTime t{2190, 518400.0};
  // PRN 14 and 18: IODC differs from IODE in the high bits; they must be accepted.
  for (int prn : {14, 18}) {
    const auto e = select_ephemeris(nav.ephemerides, prn, t);
    ASSERT_TRUE(e.has_value()) << "PRN " << prn;
    EXPECT_NE(e->iodc, e->iode);
    EXPECT_EQ(e->iodc & 0xff, e->iode);
    EXPECT_DOUBLE_EQ(e->toe_s, 518400.0);
  }
  EXPECT_FALSE(select_ephemeris(nav.ephemerides, 28, t).has_value());
  EXPECT_TRUE(select_ephemeris(nav.ephemerides, 28, t, {.include_unhealthy = true}).has_value());
  // Every healthy PRN has a set at 00:00 and the chosen toe is the nearest one (00:00 exactly).
  int found = 0;
  for (int prn = 1; prn <= 32; ++prn) {
    const auto e = select_ephemeris(nav.ephemerides, prn, t);
    if (!e) continue;
    ++found;
    EXPECT_LE(std::abs(seconds_between(t, e->toe())), 3600.0) << "PRN " << prn;
  }
  EXPECT_GE(found, 29);
  // At 01:59 the 02:00 set is the nearest for PRN 1.
  const auto e1 = select_ephemeris(nav.ephemerides, 1, {2190, 518400.0 + 7140.0});
  ASSERT_TRUE(e1.has_value());
  EXPECT_DOUBLE_EQ(e1->toe_s, 525600.0);
}

// The shipped brdc3540_0000-0200.14n (tests/data/README.md): PRN 8 is flagged unhealthy; PRNs 1, 3, 12 and 22 have
// an extra set with toe 01:59:44 (525584) beside the 02:00 one, so "nearest toe" chooses between sets 16 s apart.
TEST(EphemerisSelection, ShippedFileKnownCases) {
  const RinexNavData nav = read_rinex_nav(ultratrack::test::shipped_nav_file());
  const GpsTime t{ultratrack::test::shipped_nav_week, ultratrack::test::shipped_nav_tow_s};
  EXPECT_FALSE(select_ephemeris(nav.ephemerides, 8, t).has_value());
  const auto unhealthy = select_ephemeris(nav.ephemerides, 8, t, {.include_unhealthy = true});
  ASSERT_TRUE(unhealthy.has_value());
  EXPECT_EQ(unhealthy->health, 63);
  // Every other PRN has its 00:00 set chosen at 00:00.
  int found = 0;
  for (int prn = 1; prn <= 32; ++prn) {
    const auto e = select_ephemeris(nav.ephemerides, prn, t);
    if (!e) continue;
    ++found;
    EXPECT_DOUBLE_EQ(e->toe_s, 518400.0) << "PRN " << prn;
  }
  EXPECT_EQ(found, 31);
  // PRN 1 at 01:59:00: the 01:59:44 set (IODE 5) is nearer than the 02:00 one (IODE 94); at 02:00:00 the 02:00 set.
  const auto early = select_ephemeris(nav.ephemerides, 1, add_seconds(t, 7140.0));
  ASSERT_TRUE(early.has_value());
  EXPECT_DOUBLE_EQ(early->toe_s, 525584.0);
  EXPECT_EQ(early->iode, 5);
  const auto on_time = select_ephemeris(nav.ephemerides, 1, add_seconds(t, 7200.0));
  ASSERT_TRUE(on_time.has_value());
  EXPECT_EQ(on_time->iode, 94);
  // Past the last fit interval (02:00 + 2 h) nothing is valid.
  EXPECT_FALSE(select_ephemeris(nav.ephemerides, 1, add_seconds(t, 14401.0)).has_value());
}

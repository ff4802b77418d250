// SPDX-License-Identifier: GPL-3.0-or-later
// Ephemeris selection: health, IODE/IODC consistency, fit interval and nearest toe, on the shipped
// brdc3540_0000-0200.14n (PRN 8 unhealthy, 01:59:44 sets), on a copy of it with edited IODCs (high bits set, a
// mismatch) and on hand-made sets for the rules.
#include "signals/ephemeris_selection.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <string>

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

// A real file whose IODC differs from the IODE in its two high bits (as brdc0010.22n's PRN 14 and 18 do), and one whose
// IODC does not match at all: the shipped file with PRN 1's 00:00 record edited (IODE 92; the IODC field, last of the
// record's seventh line, 92 in the file) to 348 = 256 + 92, and PRN 3's (IODE 70) to 71.
TEST(EphemerisSelection, ShippedFileWithEditedIodcs) {
  const auto edited = ultratrack::test::scratch_dir() / "iodc.14n";
  {
    std::ifstream in(ultratrack::test::shipped_nav_file());
    std::ofstream out(edited);
    std::string line;
    int record_line = -1;  // 0-7 within a record after the header
    int edit_prn = 0;      // PRN of the record being read when it is one to edit, else 0
    while (std::getline(in, line)) {
      if (record_line >= 0) {
        record_line = (record_line + 1) % 8;
        if (record_line == 0) {
          const int prn = std::stoi(line.substr(0, 2));
          const bool at_midnight = line.substr(2, 20) == " 14 12 20  0  0  0.0";
          edit_prn = at_midnight && (prn == 1 || prn == 3) ? prn : 0;
        }
        if (record_line == 6 && edit_prn != 0) {
          EXPECT_EQ(line.substr(60, 19), edit_prn == 1 ? " 0.920000000000D+02" : " 0.700000000000D+02");
          line.replace(60, 19, edit_prn == 1 ? " 0.348000000000D+03" : " 0.710000000000D+02");
        }
      } else if (line.find("END OF HEADER") != std::string::npos) {
        record_line = 7;  // the next line starts a record
      }
      out << line << '\n';
    }
  }
  const RinexNavData nav = read_rinex_nav(edited);
  const GpsTime t{ultratrack::test::shipped_nav_week, ultratrack::test::shipped_nav_tow_s};
  // PRN 1: IODC 348 carries IODE 92 in its low eight bits: accepted, the 00:00 set.
  const auto one = select_ephemeris(nav.ephemerides, 1, t);
  ASSERT_TRUE(one.has_value());
  EXPECT_EQ(one->iodc, 348);
  EXPECT_EQ(one->iode, 92);
  EXPECT_DOUBLE_EQ(one->toe_s, 518400.0);
  // PRN 3: IODC 71 against IODE 70: that set is refused and the nearest consistent one, the 01:59:44 set (7184 s
  // ahead, inside its 2 h half fit interval), is taken instead.
  const auto three = select_ephemeris(nav.ephemerides, 3, t);
  ASSERT_TRUE(three.has_value());
  EXPECT_EQ(three->iodc & 0xff, three->iode);
  EXPECT_DOUBLE_EQ(three->toe_s, 525584.0);
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

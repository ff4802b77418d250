// SPDX-License-Identifier: GPL-3.0-or-later
// GPS time: checked against published calendar anchors (GPS epoch, week rollovers, leap seconds).
#include "signals/gps_time.hpp"

#include <gtest/gtest.h>

using namespace ultratrack::signals;

TEST(GpsTime, EpochIsWeekZero) {
  const GpsTime t = gps_time_from_calendar({1980, 1, 6, 0, 0, 0.0});
  EXPECT_EQ(t.week, 0);
  EXPECT_DOUBLE_EQ(t.tow_s, 0.0);
}

TEST(GpsTime, FirstRolloverIsAugust1999) {
  // The first 10-bit week rollover happened at 1999-08-22 00:00:00 GPST (week 1024).
  const GpsTime t = gps_time_from_calendar({1999, 8, 22, 0, 0, 0.0});
  EXPECT_EQ(t.week, 1024);
  EXPECT_DOUBLE_EQ(t.tow_s, 0.0);
}

TEST(GpsTime, NewYear2022IsWeek2190Saturday) {
  // The seed scenario: 2022-01-01 00:00:00 GPST is week 2190, TOW 518400 s (a Saturday).
  const GpsTime t = gps_time_from_calendar({2022, 1, 1, 0, 0, 0.0});
  EXPECT_EQ(t.week, 2190);
  EXPECT_DOUBLE_EQ(t.tow_s, 518400.0);
}

TEST(GpsTime, CalendarRoundTrip) {
  for (int week : {0, 1023, 1024, 2047, 2048, 2190, 3000}) {
    for (double tow : {0.0, 0.5, 86399.25, 518400.0, 604799.5}) {
      const CalendarTime c = calendar_from_gps_time({week, tow});
      const GpsTime back = gps_time_from_calendar(c);
      EXPECT_EQ(back.week, week);
      EXPECT_NEAR(back.tow_s, tow, 1e-9);
    }
  }
}

TEST(GpsTime, AddSecondsCrossesWeekBoundary) {
  const GpsTime t = add_seconds({2190, 604799.0}, 2.0);
  EXPECT_EQ(t.week, 2191);
  EXPECT_DOUBLE_EQ(t.tow_s, 1.0);
  const GpsTime u = add_seconds({2191, 1.0}, -2.0);
  EXPECT_EQ(u.week, 2190);
  EXPECT_DOUBLE_EQ(u.tow_s, 604799.0);
  EXPECT_DOUBLE_EQ(seconds_between({2191, 1.0}, {2190, 604799.0}), 2.0);
}

TEST(GpsTime, WrapHalfWeek) {
  EXPECT_DOUBLE_EQ(wrap_half_week(302400.0), -302400.0);
  EXPECT_DOUBLE_EQ(wrap_half_week(-302401.0), 302399.0);
  EXPECT_DOUBLE_EQ(wrap_half_week(100.0), 100.0);
}

TEST(GpsTime, LeapSecondsFromPublishedTable) {
  EXPECT_EQ(leap_seconds_at(gps_time_from_calendar({1980, 6, 1, 0, 0, 0})), 0);
  EXPECT_EQ(leap_seconds_at(gps_time_from_calendar({2016, 6, 1, 0, 0, 0})), 17);
  EXPECT_EQ(leap_seconds_at(gps_time_from_calendar({2022, 1, 1, 0, 0, 0})), 18);
  // UTC 2017-01-01 00:00:00 is the first second with 18; GPST is then 00:00:18.
  EXPECT_EQ(leap_seconds_at(gps_time_from_calendar({2017, 1, 1, 0, 0, 17.5})), 17);
  EXPECT_EQ(leap_seconds_at(gps_time_from_calendar({2017, 1, 1, 0, 0, 18.0})), 18);
}

TEST(GpsTime, UtcConversionUsesLeapSeconds) {
  const GpsTime t = gps_time_from_utc({2022, 1, 1, 0, 0, 0.0}, 18);
  EXPECT_EQ(t.week, 2190);
  EXPECT_DOUBLE_EQ(t.tow_s, 518418.0);
  const CalendarTime u = utc_from_gps_time(t, 18);
  EXPECT_EQ(u.year, 2022);
  EXPECT_EQ(u.hour, 0);
  EXPECT_DOUBLE_EQ(u.second, 0.0);
}

TEST(GpsTime, WeekRolloverResolvedNearReference) {
  EXPECT_EQ(resolve_week_rollover(2190 % 1024, 2190), 2190);
  EXPECT_EQ(resolve_week_rollover(2190 % 1024, 2300), 2190);
  EXPECT_EQ(resolve_week_rollover(1023, 2048), 2047);  // just before the second rollover
  EXPECT_EQ(resolve_week_rollover(0, 2047), 2048);     // just after it
  EXPECT_EQ(resolve_week_rollover(100, 100), 100);
}

// SPDX-License-Identifier: GPL-3.0-or-later
#include "signals/gps_time.hpp"

#include <fmt/core.h>

#include <array>
#include <cmath>

#include "signals/gps_constants.hpp"

namespace ultratrack::signals {
namespace {

// Days from 1970-01-01 to a proleptic Gregorian date (Howard Hinnant's civil-days algorithm).
long days_from_civil(int y, int m, int d) {
  y -= m <= 2;
  const long era = (y >= 0 ? y : y - 399) / 400;
  const long yoe = y - era * 400;
  const long doy = (153 * (m + (m > 2 ? -3 : 9)) + 2) / 5 + d - 1;
  const long doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
  return era * 146097 + doe - 719468;
}

void civil_from_days(long z, int& y, int& m, int& d) {
  z += 719468;
  const long era = (z >= 0 ? z : z - 146096) / 146097;
  const long doe = z - era * 146097;
  const long yoe = (doe - doe / 1460 + doe / 36524 - doe / 146096) / 365;
  const long doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
  const long mp = (5 * doy + 2) / 153;
  d = static_cast<int>(doy - (153 * mp + 2) / 5 + 1);
  m = static_cast<int>(mp < 10 ? mp + 3 : mp - 9);
  y = static_cast<int>(yoe + era * 400 + (m <= 2));
}

const long kGpsEpochDays = days_from_civil(1980, 1, 6);

// GPST at which each leap second took effect (UTC midnight + accumulated offset), and GPST - UTC after it.
struct LeapEntry {
  int year, month, day;
  int gpst_minus_utc_s;
};
constexpr std::array<LeapEntry, 18> kLeapTable{{
    {1981, 7, 1, 1},
    {1982, 7, 1, 2},
    {1983, 7, 1, 3},
    {1985, 7, 1, 4},
    {1988, 1, 1, 5},
    {1990, 1, 1, 6},
    {1991, 1, 1, 7},
    {1992, 7, 1, 8},
    {1993, 7, 1, 9},
    {1994, 7, 1, 10},
    {1996, 1, 1, 11},
    {1997, 7, 1, 12},
    {1999, 1, 1, 13},
    {2006, 1, 1, 14},
    {2009, 1, 1, 15},
    {2012, 7, 1, 16},
    {2015, 7, 1, 17},
    {2017, 1, 1, 18},
}};

}  // namespace

double wrap_half_week(double dt_s) {
  const double half = kSecondsPerWeek / 2.0;
  while (dt_s >= half) dt_s -= kSecondsPerWeek;
  while (dt_s < -half) dt_s += kSecondsPerWeek;
  return dt_s;
}

GpsTime normalised(GpsTime t) {
  const double weeks = std::floor(t.tow_s / kSecondsPerWeek);
  t.week += static_cast<int>(weeks);
  t.tow_s -= weeks * kSecondsPerWeek;
  if (t.tow_s >= kSecondsPerWeek) {  // guards the rounding of the subtraction above
    t.tow_s -= kSecondsPerWeek;
    ++t.week;
  }
  return t;
}

double seconds_between(const GpsTime& a, const GpsTime& b) {
  return static_cast<double>(a.week - b.week) * kSecondsPerWeek + (a.tow_s - b.tow_s);
}

GpsTime add_seconds(const GpsTime& t, double dt_s) { return normalised({t.week, t.tow_s + dt_s}); }

GpsTime gps_time_from_calendar(const CalendarTime& c) {
  const long days = days_from_civil(c.year, c.month, c.day) - kGpsEpochDays;
  const long week = days >= 0 ? days / 7 : (days - 6) / 7;
  const long day_of_week = days - week * 7;
  return normalised({static_cast<int>(week), day_of_week * 86400.0 + c.hour * 3600.0 + c.minute * 60.0 + c.second});
}

CalendarTime calendar_from_gps_time(const GpsTime& t_in) {
  const GpsTime t = normalised(t_in);
  const long day_of_week = static_cast<long>(std::floor(t.tow_s / 86400.0));
  double sod = t.tow_s - day_of_week * 86400.0;
  CalendarTime c;
  civil_from_days(kGpsEpochDays + static_cast<long>(t.week) * 7 + day_of_week, c.year, c.month, c.day);
  c.hour = static_cast<int>(sod / 3600.0);
  sod -= c.hour * 3600.0;
  c.minute = static_cast<int>(sod / 60.0);
  c.second = sod - c.minute * 60.0;
  return c;
}

GpsTime gps_time_from_utc(const CalendarTime& utc, int leap_seconds) {
  return add_seconds(gps_time_from_calendar(utc), leap_seconds);
}

CalendarTime utc_from_gps_time(const GpsTime& t, int leap_seconds) {
  return calendar_from_gps_time(add_seconds(t, -leap_seconds));
}

int leap_seconds_at(const GpsTime& t) {
  int leap = 0;
  for (const auto& entry : kLeapTable) {
    // The entry takes effect at UTC midnight, which is GPST midnight + the new offset.
    const GpsTime effective = gps_time_from_calendar({entry.year, entry.month, entry.day, 0, 0, 0.0});
    if (seconds_between(t, effective) >= entry.gpst_minus_utc_s) leap = entry.gpst_minus_utc_s;
  }
  return leap;
}

int resolve_week_rollover(int week_mod_1024, int reference_full_week) {
  int week = reference_full_week - ((reference_full_week - week_mod_1024) % 1024 + 1024) % 1024;
  if (reference_full_week - week > 512) week += 1024;
  return week;
}

std::string to_string(const CalendarTime& c) {
  return fmt::format("{:04d}-{:02d}-{:02d} {:02d}:{:02d}:{:06.3f}", c.year, c.month, c.day, c.hour, c.minute, c.second);
}

}  // namespace ultratrack::signals

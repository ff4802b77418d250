// SPDX-License-Identifier: GPL-3.0-or-later
// GPS system time as (week, seconds of week) and conversions to the calendar (GPST and UTC) for RINEX.
// Week numbers here are full (continuous) weeks since 1980-01-06; the 10-bit broadcast week is resolved
// against a reference full week explicitly (resolve_week_rollover). Absolute time is never a single float.
#pragma once

#include <cstdint>
#include <string>

namespace ultratrack::signals {

struct GpsTime {
  int week = 0;        // full GPS week number (no 1024 rollover)
  double tow_s = 0.0;  // seconds of week, [0, 604800)
};

// A broken-down calendar date and time (no time zone: the caller says whether it is GPST or UTC).
struct CalendarTime {
  int year = 1980, month = 1, day = 6, hour = 0, minute = 0;
  double second = 0.0;
};

// a - b in seconds (exact to double precision of the difference, not of the absolute times).
double seconds_between(const GpsTime& a, const GpsTime& b);
// t + dt_s, normalised so that tow_s lies in [0, 604800).
GpsTime add_seconds(const GpsTime& t, double dt_s);
// Normalise any (week, tow) pair so that tow_s lies in [0, 604800).
GpsTime normalised(GpsTime t);
// Time difference of two seconds-of-week values wrapped into [-302400, 302400) (IS-GPS-200 20.3.3.4.3 t_k).
double wrap_half_week(double dt_s);

GpsTime gps_time_from_calendar(const CalendarTime& gpst);
CalendarTime calendar_from_gps_time(const GpsTime& t);

// UTC <-> GPST with an explicit leap-second count (GPST - UTC, 18 s since 2017-01-01).
GpsTime gps_time_from_utc(const CalendarTime& utc, int leap_seconds);
CalendarTime utc_from_gps_time(const GpsTime& t, int leap_seconds);
// The leap-second count in force at a GPS time, from the built-in table of published leap seconds.
int leap_seconds_at(const GpsTime& t);

// Full week from a broadcast week modulo 1024 (LNAV) that is nearest to reference_full_week.
int resolve_week_rollover(int week_mod_1024, int reference_full_week);

// "2022-01-01 00:00:00.000" style text for logs and files.
std::string to_string(const CalendarTime& c);

}  // namespace ultratrack::signals

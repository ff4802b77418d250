// SPDX-License-Identifier: GPL-3.0-or-later
// RINEX GPS navigation files: a reader for versions 2.xx (GPS 'N' files) and 3.00-3.05 (GPS or mixed:
// only 'G' records are kept, other systems are skipped by their record lengths), and a writer of RINEX
// 3.04 GPS navigation. Ephemerides come out in SI units (RINEX already uses radians and rad/s).
#pragma once

#include <filesystem>
#include <istream>
#include <string>
#include <vector>

#include "signals/ephemeris.hpp"

namespace ultratrack::signals {

struct RinexNavData {
  double version = 3.04;
  std::vector<Ephemeris> ephemerides;  // GPS records in file order
  std::vector<double> transmit_tow_s;  // per record: transmission time of message (s of week), as read
  KlobucharParameters klobuchar;       // ION ALPHA/BETA (2.xx) or IONOSPHERIC CORR GPSA/GPSB (3.xx)
  UtcParameters utc;                   // DELTA-UTC (2.xx) or TIME SYSTEM CORR GPUT (3.xx); leap seconds
  bool has_leap_seconds = false;       // a LEAP SECONDS line was present (value in utc.delta_t_ls_s)
};

// Reads a RINEX navigation file. Throws InputError (file, line, problem) on a missing/empty file, bad
// header, wrong version or type, unparseable number or truncated record.
RinexNavData read_rinex_nav(const std::filesystem::path& path);
// The same from a stream; `name` is used in error messages.
RinexNavData read_rinex_nav(std::istream& in, const std::string& name);

// Writes RINEX 3.04 GPS navigation (header with GPSA/GPSB, GPUT and LEAP SECONDS when valid, then one
// record per ephemeris). The file is written to a temporary name and renamed when complete. An unknown
// transmission time (transmit_tow_s shorter than ephemerides) is written as the toe. Throws InputError
// when the file cannot be written.
void write_rinex_nav_304(const std::filesystem::path& path, const RinexNavData& data);

// URA index (IS-GPS-200 20.3.3.3.1.3) <-> the accuracy in metres that RINEX stores (upper bound of the
// index's range; index 15 is written as 12288 m, "no accuracy prediction").
int ura_index_from_metres(double ura_m);
double ura_metres_from_index(int ura_index);

// Curve-fit interval in hours of an ephemeris (IS-GPS-200 20.3.4.4): 4 h for fit flag 0; for flag 1 the
// IODC-dependent value of the IS-GPS-200 table for extended operations (6 h unless the IODC is listed).
double fit_interval_hours(const Ephemeris& eph);

}  // namespace ultratrack::signals

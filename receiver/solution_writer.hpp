// SPDX-License-Identifier: GPL-3.0-or-later
// The receiver's standard outputs for navigation solutions, each streamed to an AtomicFile and made
// visible only by finish():
//   solution.csv  one row per fix (columns in kSolutionCsvHeader; lat/lon in degrees, heights ellipsoidal)
//   NMEA 0183     GGA, RMC, GSA, GSV per fix (UTC = GPST - leap seconds; altitude ellipsoidal with a
//                 geoid separation of 0, since no geoid model ships with the Debian packages we use)
//   KML           the track as a LineString plus a placemark at the mean position
#pragma once

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "io/atomic_file.hpp"
#include "receiver/pvt.hpp"

namespace ultratrack::receiver {

inline constexpr const char* kSolutionCsvHeader =
    "gps_week,tow_s,lat_deg,lon_deg,height_m,ecef_x_m,ecef_y_m,ecef_z_m,vel_e_mps,vel_n_mps,vel_u_mps,"
    "clock_bias_m,clock_drift_mps,num_sats,pdop,hdop,vdop,excluded_prn";

class SolutionCsvWriter {
 public:
  explicit SolutionCsvWriter(const std::filesystem::path& path);
  void write(const PvtSolution& fix);
  void finish() { file_.commit(); }

 private:
  io::AtomicFile file_;
};

class NmeaWriter {
 public:
  NmeaWriter(const std::filesystem::path& path, int leap_seconds);
  void write(const PvtSolution& fix);
  void finish() { file_.commit(); }

 private:
  io::AtomicFile file_;
  int leap_seconds_;
};

// "$<body>*HH" with the NMEA checksum (XOR of the body's characters).
std::string nmea_sentence(const std::string& body);

class KmlWriter {
 public:
  explicit KmlWriter(const std::filesystem::path& path);
  void write(const PvtSolution& fix);
  void finish();

 private:
  io::AtomicFile file_;
  std::vector<std::string> coordinates_;  // "lon,lat,h" per fix (small: a few dozen bytes per fix)
  double sum_lat_deg_ = 0.0, sum_lon_deg_ = 0.0, sum_h_m_ = 0.0;
};

}  // namespace ultratrack::receiver

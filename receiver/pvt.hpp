// SPDX-License-Identifier: GPL-3.0-or-later
// Position, velocity and time from one epoch of pseudoranges and Doppler: iterated weighted least squares
// in ECEF (WGS-84) with the satellite clock, relativity, TGD, Sagnac, broadcast ionosphere and troposphere
// corrections, an elevation mask, a chi-square residual test that excludes one faulty satellite, velocity
// and clock drift from Doppler, and DOPs (a GDOP above PvtOptions::max_gdop: no solution). Units: metres, m/s, seconds;
// angles in radians.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "signals/ephemeris.hpp"
#include "signals/gps_time.hpp"

namespace ultratrack::receiver {

// One satellite's measurements at the common receive epoch.
struct SatelliteMeasurement {
  int prn = 0;
  double pseudorange_m = 0.0;  // c * (receive time by the receiver clock - transmit time by the SV clock)
  double doppler_hz = 0.0;     // carrier Doppler, positive when the range shrinks
  bool has_doppler = false;
  double cn0_dbhz = 45.0;
  signals::Ephemeris ephemeris;
};

struct PvtOptions {
  double elevation_mask_rad = 10.0 * 3.14159265358979 / 180.0;
  bool ionosphere = true;   // broadcast Klobuchar (needs valid parameters)
  bool troposphere = true;  // standard troposphere model
  bool exclude_unhealthy = true;
  bool fault_exclusion = true;            // chi-square residual test, excludes at most one satellite
  double false_alarm_probability = 1e-3;  // of the residual test
  double sigma_zenith_m = 1.0;      // pseudorange 1-sigma at zenith and 45 dB-Hz; grows with 1/sin(el), lower C/N0
  double sigma_doppler_mps = 0.05;  // range-rate 1-sigma at zenith and 45 dB-Hz
  int max_iterations = 10;
  // A solution whose GDOP exceeds this is no solution (RTKLIB's pos2-rejgdop, default 30): with 4-5 satellites
  // nearly on one cone the geometry turns metres of range noise into kilometres (a 24 dB-Hz file: PDOP 310, fixes
  // 0.7-2.3 km off, docs/validation.md).
  double max_gdop = 30.0;

  // Empty when valid, else the reason.
  // True when the options fit together; otherwise false and *why (when given) says which setting and why.
  bool IsValid(std::string* why) const;
};

// A satellite used in a solution, with its geometry as seen from the solved position.
struct UsedSatellite {
  int prn = 0;
  double elevation_rad = 0.0, azimuth_rad = 0.0;
  double residual_m = 0.0;  // measured minus predicted pseudorange after the solve
  double cn0_dbhz = 0.0;
};

struct PvtSolution {
  bool valid = false;
  std::string failure;    // why no solution (when !valid)
  signals::GpsTime time;  // receive time corrected by the clock bias (GPS system time)
  Eigen::Vector3d r_e_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d v_e_mps = Eigen::Vector3d::Zero();
  bool velocity_valid = false;
  double clock_bias_m = 0.0;     // c * receiver clock offset (receiver clock - GPS time)
  double clock_drift_mps = 0.0;  // c * receiver clock drift
  double lat_rad = 0.0, lon_rad = 0.0, height_m = 0.0;
  Eigen::Vector3d v_enu_mps = Eigen::Vector3d::Zero();
  double gdop = 0.0, pdop = 0.0, hdop = 0.0, vdop = 0.0, tdop = 0.0;
  std::vector<int> used_prns;
  std::vector<UsedSatellite> satellites;  // the used ones, same order as used_prns
  std::optional<int> excluded_prn;        // removed by the residual test
  double residual_rms_m = 0.0;
  int iterations = 0;
  // A-priori covariances of the weighted solutions (the inverse normal matrices with the elevation and C/N0
  // sigma model above): ECEF position + c * clock bias [m^2], ECEF velocity + c * clock drift [(m/s)^2]
  // (zero when velocity_valid is false).
  Eigen::Matrix4d covariance_m2 = Eigen::Matrix4d::Zero();
  Eigen::Matrix4d velocity_covariance_m2ps2 = Eigen::Matrix4d::Zero();
};

// Solves one epoch. receive_time is the epoch by the receiver's clock. initial_r_e_m seeds the iteration
// (the earth's centre works; a previous fix converges faster). Needs at least 4 usable satellites.
PvtSolution solve_pvt(const std::vector<SatelliteMeasurement>& measurements, const signals::GpsTime& receive_time,
                      const signals::KlobucharParameters& iono, const PvtOptions& options,
                      const Eigen::Vector3d& initial_r_e_m = Eigen::Vector3d::Zero());

}  // namespace ultratrack::receiver

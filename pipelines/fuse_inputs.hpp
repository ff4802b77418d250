// SPDX-License-Identifier: GPL-3.0-or-later
// The external measurements `fuse` takes besides the IMU increments: GNSS fixes on the IMU time line (a geodetic
// antenna position, optional NED velocity, NED position 1-sigmas) and GPS attitude rows of a multi-antenna receiver
// (GPS time tags; angles of the antenna-array frame relative to NED). pipelines/gnss_fix_csv.hpp and
// pipelines/gps_attitude_csv.hpp read them from files. Units: rad, m, m/s, s.
#pragma once

#include <Eigen/Core>

#include "ins/attitude.hpp"
#include "signals/gps_time.hpp"

namespace ultratrack::pipelines {

struct GnssFixRow {
  double t_s = 0.0;
  double lat_rad = 0.0, lon_rad = 0.0, height_m = 0.0;
  bool has_velocity = false;
  Eigen::Vector3d v_n = Eigen::Vector3d::Zero();          // m/s, valid when has_velocity
  Eigen::Vector3d sigma_ned_m = Eigen::Vector3d::Ones();  // 1-sigma north, east, down position error
};

struct GpsAttitudeRow {
  int line = 0;  // in the file, for messages
  signals::GpsTime time;
  ins::EulerAngles euler;  // rad (nan when not fixed)
  double sigma_roll_rad = 0.0, sigma_pitch_rad = 0.0, sigma_yaw_rad = 0.0;
  int num_sats = 0;
  bool fixed = false;
  double ratio = 0.0;
};

}  // namespace ultratrack::pipelines

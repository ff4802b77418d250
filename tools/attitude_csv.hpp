// Reader of the multi-antenna receiver's attitude.csv (tools/attitude_outputs.hpp, `ultratrack attitude`) for
// `ultratrack fuse --attitude`: gps_week,tow_s,roll_deg,pitch_deg,yaw_deg,sigma_roll_deg,sigma_pitch_deg,
// sigma_yaw_deg,num_sats,fixed,ratio. Angles of the antenna-array frame relative to NED; GPS time tags.
// Rows with fixed = 0 may carry nan angles (no validated attitude); a fixed row needs finite angles in range and
// positive sigmas. Times strictly increasing. Anything else is an InputError naming the file and line.
#pragma once

#include <filesystem>
#include <vector>

#include "ins/attitude.hpp"
#include "signals/gps_time.hpp"

namespace ultratrack::tools {

struct AttitudeCsvRow {
  int line = 0;  // in the file, for messages
  signals::GpsTime time;
  ins::EulerAngles euler;                                      // rad (nan when not fixed)
  double sigma_roll_rad = 0.0, sigma_pitch_rad = 0.0, sigma_yaw_rad = 0.0;
  int num_sats = 0;
  bool fixed = false;
  double ratio = 0.0;
};

std::vector<AttitudeCsvRow> read_attitude_csv(const std::filesystem::path& file);

}  // namespace ultratrack::tools

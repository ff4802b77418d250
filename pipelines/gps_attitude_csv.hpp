// SPDX-License-Identifier: GPL-3.0-or-later
// Reader of the multi-antenna receiver's attitude.csv (receiver/attitude_outputs.hpp, `ultratrack attitude`) for
// `ultratrack fuse --attitude`: gps_week,tow_s,roll_deg,pitch_deg,yaw_deg,sigma_roll_deg,sigma_pitch_deg,
// sigma_yaw_deg,num_sats,fixed,ratio. Angles of the antenna-array frame relative to NED; GPS time tags.
// Rows with fixed = 0 may carry nan angles (no validated attitude); a fixed row needs finite angles in range and
// positive sigmas. Times strictly increasing. Anything else is an InputError naming the file and line.
#pragma once

#include <filesystem>
#include <vector>

#include "pipelines/fuse_inputs.hpp"

namespace ultratrack::pipelines {

using AttitudeCsvRow = pipelines::GpsAttitudeRow;  // the row (pipelines/fuse_inputs.hpp); this file reads it

std::vector<AttitudeCsvRow> read_attitude_csv(const std::filesystem::path& file);

}  // namespace ultratrack::pipelines

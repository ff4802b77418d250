// SPDX-License-Identifier: GPL-3.0-or-later
// External GNSS fixes for `ultratrack fuse`: the CSV
// `t_s,lat_deg,lon_deg,height_m,vel_n_mps,vel_e_mps,vel_d_mps,sigma_n_m,sigma_e_m,sigma_d_m`
// (WGS-84 geodetic antenna position, NED velocity, 1-sigma NED position error). The three velocity fields
// may be empty together (position-only fix). t_s is on the IMU file's time line. Strict reader: anything
// malformed, non-finite, out of range or not strictly increasing in time is an InputError with file and line.
#pragma once

#include <filesystem>
#include <span>
#include <vector>

#include "pipelines/fuse_inputs.hpp"

namespace ultratrack::pipelines {

using GnssCsvRow = pipelines::GnssFixRow;  // the row (pipelines/fuse_inputs.hpp); this file reads and writes it

std::vector<GnssCsvRow> read_gnss_csv(const std::filesystem::path& file);

// Writes fixes with round-trip precision (empty velocity fields where has_velocity is false), atomically.
void write_gnss_csv(const std::filesystem::path& file, std::span<const GnssCsvRow> fixes);

}  // namespace ultratrack::pipelines

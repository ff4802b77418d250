// SPDX-License-Identifier: GPL-3.0-or-later
// Initial state / truth for `ultratrack ins --init`: either a navigation CSV (ins/nav_csv.hpp) or the
// truth.csv of an inertial `ultratrack simulate` run (sim/simulation_files.hpp columns with roll/pitch/yaw). For
// the latter, t_s is put on the IMU's time line: true GPS time (gps_week, tow_s) since the first row, which
// is the scenario start. Throws InputError naming the file and line.
#pragma once

#include <filesystem>
#include <vector>

#include "ins/nav_state.hpp"

namespace ultratrack::sim {

std::vector<ins::NavState> read_truth_csv(const std::filesystem::path& file);

}  // namespace ultratrack::sim

// SPDX-License-Identifier: GPL-3.0-or-later
// The antenna file of `ultratrack attitude` (--antennas A.toml): the array's geometry in the scenario's
// convention, and optional solver settings. Parsed strictly (unknown keys and wrong types are InputErrors
// naming the file, the line and the key).
//
//   [[antenna]]  lever_arm_body_m = [x, y, z]   body axes (x forward, y right, z down), m; the first is the master
//                line_bias_cycles = 0.0         known carrier line bias of the antenna (RINEX sense), subtracted
//                                                from its phase before the solver; phase_noise_m is accepted and
//                                                ignored (a scenario's [[antenna]] tables can be copied as they are)
//   [solver]     phase_sigma_m = 0.003  elevation_mask_deg = 10.0  ratio_threshold = 2.0  min_satellites = 5
//                use_length_constraint = true  multi_epoch = true
#pragma once

#include <filesystem>
#include <vector>

#include "receiver/attitude_solver.hpp"

namespace ultratrack::config {

struct AntennaConfig {
  receiver::AttitudeSolverOptions solver;  // solver.array from the [[antenna]] tables
  std::vector<double> line_bias_cycles;    // per antenna
};

// Throws InputError: missing file, syntax, unknown key, wrong type, fewer than 2 or more than kMaxAntennas
// antennas, or solver options that do not validate.
AntennaConfig read_antenna_config(const std::filesystem::path& path);

}  // namespace ultratrack::config

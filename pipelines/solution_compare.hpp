// SPDX-License-Identifier: GPL-3.0-or-later
// A receiver's solution.csv against a simulation's truth.csv (`ultratrack compare`, the synthetic acceptance
// tests): each fix is set against the truth interpolated at the fix's TRUE GPS time (receiver time minus the
// fix's own clock bias), position errors in the local east-north-up frame of the truth point, velocity errors
// in ENU. Columns are found by name, so later columns in either file do not matter. Units: m, m/s, s.
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <string>
#include <vector>

namespace ultratrack::pipelines {

// One solution.csv row (receiver/solution_writer.hpp), the fields the comparison needs.
struct SolutionFix {
  int gps_week = 0;
  double tow_s = 0.0;  // receiver clock time of the fix
  Eigen::Vector3d r_e_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d v_enu_mps = Eigen::Vector3d::Zero();
  double clock_bias_m = 0.0;
  int num_sats = 0;
};

// One truth.csv row of `ultratrack simulate` (true GPS time, antenna / IMU position and NED velocity).
struct TruthPoint {
  int gps_week = 0;
  double tow_s = 0.0;
  Eigen::Vector3d r_e_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d v_ned_mps = Eigen::Vector3d::Zero();
};

// Throw io::InputError (file, problem, line) for a missing column, a malformed number or an empty file.
std::vector<SolutionFix> read_solution_csv(const std::filesystem::path& file);
std::vector<TruthPoint> read_simulation_truth_csv(const std::filesystem::path& file);

struct ComparisonOptions {
  double skip_s = 0.0;  // fixes in the first skip_s seconds after the first fix are left out (settling)
};

struct SolutionComparison {
  int fixes = 0;                               // fixes compared (inside the truth's time span, after skip_s)
  int fixes_outside_truth = 0;                 // fixes whose time the truth does not cover (not compared)
  double first_tow_s = 0.0, last_tow_s = 0.0;  // receiver times of the first / last fix compared
  double rms_3d_m = 0.0, rms_horizontal_m = 0.0, rms_vertical_m = 0.0, max_3d_m = 0.0;
  Eigen::Vector3d mean_enu_m = Eigen::Vector3d::Zero();   // bias of the position errors
  double rms_velocity_mps = 0.0, max_velocity_mps = 0.0;  // 3-D
  double rms_velocity_horizontal_mps = 0.0, rms_velocity_vertical_mps = 0.0;
};

// truth must be in increasing time (as simulate writes it). Fixes outside its span are counted, not compared.
SolutionComparison compare_solution(const std::vector<SolutionFix>& solution, const std::vector<TruthPoint>& truth,
                                    const ComparisonOptions& options = {});

// The comparison as a JSON object (one line per key).
std::string to_json(const SolutionComparison& c);

}  // namespace ultratrack::pipelines

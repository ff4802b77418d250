// SPDX-License-Identifier: GPL-3.0-or-later
// Simulated external GNSS fixes from a truth trajectory (for `ultratrack gnsssim`, tests and the loose
// integration figures): position (and optionally velocity) of an antenna at lever_arm_b at times
// t0 + k / rate, with first-order Gauss-Markov position errors (white when correlation_time_s = 0), an optional white
// part on top, and white (or Gauss-Markov) velocity errors, from a seeded generator. Units SI; NED errors; times on the
// truth's time line.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <vector>

#include "ins/nav_state.hpp"
#include "ins/truth_interpolator.hpp"
#include "pipelines/gnss_fix_csv.hpp"

namespace ultratrack::pipelines {

struct GnssFixSimulationOptions {
  double rate_hz = 1.0;
  double first_time_s = 0.0;                   // time of the first fix (clamped into the truth span)
  Eigen::Vector3d sigma_ned_m{1.5, 1.5, 3.0};  // steady-state 1-sigma position error (and the column)
  double correlation_time_s = 0.0;             // 0: white position errors
  // A white part on top (a receiver's fixes hold both): 0 none. The file's sigma columns are then the total,
  // sqrt(sigma^2 + white^2), unless stated_sigma_ned_m says otherwise (a receiver that misstates its accuracy).
  Eigen::Vector3d white_sigma_ned_m = Eigen::Vector3d::Zero();
  std::optional<Eigen::Vector3d> stated_sigma_ned_m;
  bool with_velocity = true;
  double sigma_velocity_mps = 0.05;                       // per axis (stationary 1-sigma when correlated)
  double velocity_correlation_time_s = 0.0;               // 0: white velocity errors; else Gauss-Markov
  Eigen::Vector3d lever_arm_b = Eigen::Vector3d::Zero();  // antenna in body axes from the IMU [m]
  std::uint64_t seed = 1;
};

std::vector<GnssCsvRow> simulate_gnss_fixes(const ins::TruthInterpolator& truth, const GnssFixSimulationOptions& o);

// TruthSamples from navigation rows (no body rate: the lever arm's rotational velocity is then ignored).
std::vector<ins::TruthSample> truth_samples_from_nav(const std::vector<ins::NavState>& nav);

}  // namespace ultratrack::pipelines

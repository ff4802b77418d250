// SPDX-License-Identifier: GPL-3.0-or-later
// A navigation solution's 1-sigmas as nav.csv reports them: NED position (m) and velocity (m/s), attitude as the
// psi-angle about north, east, down (rad: tilts and heading).
#pragma once

#include <Eigen/Core>

namespace ultratrack::pipelines {

struct NavSigma {
  Eigen::Vector3d position_ned_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d velocity_ned_mps = Eigen::Vector3d::Zero();
  Eigen::Vector3d attitude_ned_rad = Eigen::Vector3d::Zero();
};

}  // namespace ultratrack::pipelines

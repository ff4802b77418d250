// SPDX-License-Identifier: GPL-3.0-or-later
// The local NED frame at a geodetic position, for the simulator's truth rows and static antenna offsets.
#pragma once

#include <Eigen/Core>

#include "ins/earth_model.hpp"

namespace ultratrack::sim {

// The ECEF -> NED rotation at latitude/longitude (rad), as a plain matrix.
inline Eigen::Matrix3d ned_from_ecef(double lat_rad, double lon_rad) {
  return Eigen::Matrix3d(ins::C_en(lat_rad, lon_rad).transpose());
}

}  // namespace ultratrack::sim

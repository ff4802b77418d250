// SPDX-License-Identifier: GPL-3.0-or-later
// Azimuth and elevation of a satellite seen from a receiver, both in the same ECEF (WGS-84) frame,
// in the receiver's local east-north-up frame on the WGS-84 ellipsoid. Radians; azimuth from north
// through east in [0, 2 pi).
#pragma once

#include <Eigen/Core>

namespace ultratrack::signals {

struct LookAngles {
  double azimuth_rad = 0.0;
  double elevation_rad = 0.0;
};

LookAngles look_angles(const Eigen::Vector3d& r_rx_e, const Eigen::Vector3d& r_sat_e);

}  // namespace ultratrack::signals

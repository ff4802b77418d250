// SPDX-License-Identifier: GPL-3.0-or-later
// Look angles via GeographicLib's geodetic latitude/longitude of the receiver and the ENU rotation.
#include "signals/look_angles.hpp"

#include <GeographicLib/Geocentric.hpp>
#include <cmath>

namespace ultratrack::signals {

LookAngles look_angles(const Eigen::Vector3d& r_rx_e, const Eigen::Vector3d& r_sat_e) {
  double lat_deg = 0.0, lon_deg = 0.0, h_m = 0.0;
  GeographicLib::Geocentric::WGS84().Reverse(r_rx_e.x(), r_rx_e.y(), r_rx_e.z(), lat_deg, lon_deg, h_m);
  const double lat = lat_deg * M_PI / 180.0, lon = lon_deg * M_PI / 180.0;
  const Eigen::Vector3d d = r_sat_e - r_rx_e;
  const double sl = std::sin(lat), cl = std::cos(lat), so = std::sin(lon), co = std::cos(lon);
  const double east = -so * d.x() + co * d.y();
  const double north = -sl * co * d.x() - sl * so * d.y() + cl * d.z();
  const double up = cl * co * d.x() + cl * so * d.y() + sl * d.z();
  LookAngles a;
  a.azimuth_rad = std::atan2(east, north);
  if (a.azimuth_rad < 0.0) a.azimuth_rad += 2.0 * M_PI;
  a.elevation_rad = std::atan2(up, std::hypot(east, north));
  return a;
}

}  // namespace ultratrack::signals

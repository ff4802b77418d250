// SPDX-License-Identifier: GPL-3.0-or-later
// WGS-84 earth model for local-level NED navigation: radii of curvature, earth rate and transport rate
// in the navigation frame, normal gravity (GeographicLib, gravitation + centrifugal) and geodetic <-> ECEF.
// Units: rad, m, m/s, rad/s, m/s^2. Frames: n = NED at the point, e = ECEF.
#pragma once

#include <Eigen/Core>

namespace ultratrack::ins {

inline constexpr double kEarthRate_rps = 7.292115e-5;  // WGS-84 omega_ie

struct Radii {
  double meridian_m = 0.0;    // R_M: north-south radius of curvature
  double transverse_m = 0.0;  // R_N: prime-vertical (east-west) radius of curvature
};

Radii radii_of_curvature(double lat_rad);

// omega_ie^n = (W cos L, 0, -W sin L)
Eigen::Vector3d earth_rate_n(double lat_rad);
// omega_en^n = (v_E/(R_N+h), -v_N/(R_M+h), -v_E tan L/(R_N+h)), consistent with lat/lon rates below.
Eigen::Vector3d transport_rate_n(double lat_rad, double height_m, const Eigen::Vector3d& v_n);
// Normal gravity (gravitation plus centrifugal) in NED at (lat, h): (north, 0, down) components.
Eigen::Vector3d gravity_n(double lat_rad, double height_m);

// Geodetic position rates from the NED velocity: (dlat/dt, dlon/dt, dh/dt).
Eigen::Vector3d geodetic_rates(double lat_rad, double height_m, const Eigen::Vector3d& v_n);

Eigen::Vector3d ecef_from_geodetic(double lat_rad, double lon_rad, double height_m);
// Rotation NED -> ECEF at (lat, lon): r_e = C_en * r_n.
Eigen::Matrix3d C_en(double lat_rad, double lon_rad);

}  // namespace ultratrack::ins

// SPDX-License-Identifier: GPL-3.0-or-later
#include "ins/earth_model.hpp"

#include <GeographicLib/Constants.hpp>
#include <GeographicLib/Geocentric.hpp>
#include <GeographicLib/NormalGravity.hpp>
#include <cmath>
#include <numbers>

#include "io/units.hpp"

namespace ultratrack::ins {
namespace {}  // namespace

Radii radii_of_curvature(double lat_rad) {
  const double a = GeographicLib::Constants::WGS84_a();
  const double f = GeographicLib::Constants::WGS84_f();
  const double e2 = f * (2.0 - f);
  const double s = std::sin(lat_rad);
  const double w2 = 1.0 - e2 * s * s;
  const double w = std::sqrt(w2);
  return Radii{a * (1.0 - e2) / (w2 * w), a / w};
}

Eigen::Vector3d earth_rate_n(double lat_rad) {
  return {kEarthRate_rps * std::cos(lat_rad), 0.0, -kEarthRate_rps * std::sin(lat_rad)};
}

Eigen::Vector3d transport_rate_n(double lat_rad, double height_m, const Eigen::Vector3d& v_n) {
  const Radii r = radii_of_curvature(lat_rad);
  const double re = r.transverse_m + height_m;
  return {v_n.y() / re, -v_n.x() / (r.meridian_m + height_m), -v_n.y() * std::tan(lat_rad) / re};
}

Eigen::Vector3d gravity_n(double lat_rad, double height_m) {
  static const GeographicLib::NormalGravity& model = GeographicLib::NormalGravity::WGS84();
  double gamma_north = 0.0, gamma_up = 0.0;
  model.Gravity(lat_rad * io::kDegPerRad, height_m, gamma_north, gamma_up);
  return {gamma_north, 0.0, -gamma_up};
}

Eigen::Vector3d geodetic_rates(double lat_rad, double height_m, const Eigen::Vector3d& v_n) {
  const Radii r = radii_of_curvature(lat_rad);
  return {v_n.x() / (r.meridian_m + height_m), v_n.y() / ((r.transverse_m + height_m) * std::cos(lat_rad)), -v_n.z()};
}

Eigen::Vector3d ecef_from_geodetic(double lat_rad, double lon_rad, double height_m) {
  static const GeographicLib::Geocentric& earth = GeographicLib::Geocentric::WGS84();
  double x = 0.0, y = 0.0, z = 0.0;
  earth.Forward(lat_rad * io::kDegPerRad, lon_rad * io::kDegPerRad, height_m, x, y, z);
  return {x, y, z};
}

Eigen::Matrix3d C_en(double lat_rad, double lon_rad) {
  const double sl = std::sin(lat_rad), cl = std::cos(lat_rad);
  const double so = std::sin(lon_rad), co = std::cos(lon_rad);
  Eigen::Matrix3d m;  // columns: north, east, down unit vectors in ECEF
  // clang-format off
  m << -sl * co, -so, -cl * co,
       -sl * so,  co, -cl * so,
             cl, 0.0,      -sl;
  // clang-format on
  return m;
}

}  // namespace ultratrack::ins

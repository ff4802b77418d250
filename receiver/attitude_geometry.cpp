// SPDX-License-Identifier: GPL-3.0-or-later
#include "receiver/attitude_geometry.hpp"

#include <Eigen/Geometry>
#include <GeographicLib/Geocentric.hpp>
#include <algorithm>
#include <cmath>
#include <numbers>

namespace ultratrack::receiver {

Eigen::Matrix3d ned_to_ecef_rotation(const Eigen::Vector3d& r_e) {
  double lat_deg = 0.0, lon_deg = 0.0, h_m = 0.0;
  GeographicLib::Geocentric::WGS84().Reverse(r_e.x(), r_e.y(), r_e.z(), lat_deg, lon_deg, h_m);
  const double lat = lat_deg * std::numbers::pi / 180.0;
  const double lon = lon_deg * std::numbers::pi / 180.0;
  const double sl = std::sin(lat), cl = std::cos(lat), so = std::sin(lon), co = std::cos(lon);
  Eigen::Matrix3d C_en;
  C_en.col(0) << -sl * co, -sl * so, cl;   // north
  C_en.col(1) << -so, co, 0.0;             // east
  C_en.col(2) << -cl * co, -cl * so, -sl;  // down
  return C_en;
}

EulerAngles euler_from_C_nb(const Eigen::Matrix3d& C) {
  EulerAngles e;
  e.roll_rad = std::atan2(C(2, 1), C(2, 2));
  e.pitch_rad = std::asin(std::clamp(-C(2, 0), -1.0, 1.0));
  e.yaw_rad = std::atan2(C(1, 0), C(0, 0));
  if (e.yaw_rad < 0.0) e.yaw_rad += 2.0 * std::numbers::pi;
  return e;
}

Eigen::Matrix3d C_nb_from_euler(const EulerAngles& e) {
  return (Eigen::AngleAxisd(e.yaw_rad, Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(e.pitch_rad, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(e.roll_rad, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

Eigen::Matrix3d rotation_from_vector(const Eigen::Vector3d& v) {
  const double angle = v.norm();
  if (angle < 1e-15) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(angle, v / angle).toRotationMatrix();
}

Eigen::Matrix3d euler_covariance(const Eigen::Matrix3d& C_nb, const Eigen::Matrix3d& P_n) {
  constexpr double kStep = 1e-6;
  Eigen::Matrix3d J;
  for (int i = 0; i < 3; ++i) {
    Eigen::Vector3d d = Eigen::Vector3d::Zero();
    d(i) = kStep;
    const EulerAngles p = euler_from_C_nb(rotation_from_vector(d) * C_nb);
    const EulerAngles m = euler_from_C_nb(rotation_from_vector(-d) * C_nb);
    double dyaw = p.yaw_rad - m.yaw_rad;
    if (dyaw > std::numbers::pi) dyaw -= 2.0 * std::numbers::pi;
    if (dyaw < -std::numbers::pi) dyaw += 2.0 * std::numbers::pi;
    J.col(i) << (p.roll_rad - m.roll_rad) / (2 * kStep), (p.pitch_rad - m.pitch_rad) / (2 * kStep), dyaw / (2 * kStep);
  }
  return J * P_n * J.transpose();
}

}  // namespace ultratrack::receiver

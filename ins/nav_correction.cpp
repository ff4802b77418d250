// SPDX-License-Identifier: GPL-3.0-or-later
#include "ins/nav_correction.hpp"

#include <cmath>

#include "ins/attitude.hpp"
#include "ins/earth_model.hpp"

namespace ultratrack::ins {

Eigen::Vector3d position_error_ned(const NavState& est, const NavState& truth) {
  const Eigen::Vector3d d_e = ecef_from_geodetic(est.lat_rad, est.lon_rad, est.height_m) -
                              ecef_from_geodetic(truth.lat_rad, truth.lon_rad, truth.height_m);
  return C_en(truth.lat_rad, truth.lon_rad).transpose() * d_e;
}

void correct_position(NavState& s, const Eigen::Vector3d& dr) {
  const Radii r = radii_of_curvature(s.lat_rad);
  s.lat_rad -= dr.x() / (r.meridian_m + s.height_m);
  s.lon_rad -= dr.y() / ((r.transverse_m + s.height_m) * std::cos(s.lat_rad));
  s.height_m += dr.z();  // down error: the estimate is too low by dr.z
}

void correct_velocity(NavState& s, const Eigen::Vector3d& dv) { s.v_n -= dv; }

void correct_attitude(NavState& s, const Eigen::Vector3d& psi) {
  // C_true = (I + [psi x]) C_est to first order: rotate the estimate by +psi in the navigation frame.
  s.q_nb = (quaternion_from_rotation_vector(psi) * s.q_nb).normalized();
}

}  // namespace ultratrack::ins

// SPDX-License-Identifier: GPL-3.0-or-later
#include "ins/coarse_alignment.hpp"

#include <cmath>
#include <stdexcept>

#include "ins/earth_model.hpp"

namespace ultratrack::ins {

AlignmentResult coarse_align(const Eigen::Vector3d& f, const Eigen::Vector3d& w, double lat_rad) {
  (void)lat_rad;  // the levelled heading solution needs only the horizontal direction of earth rate
  AlignmentResult r;
  r.mean_f_b = f;
  r.mean_w_ib_b = w;
  // At rest f_b = C_bn (0, 0, -g): f_x = g sin(pitch), f_y = -g sin(roll) cos(pitch), f_z = -g cos(roll) cos(pitch).
  r.euler.roll_rad = std::atan2(-f.y(), -f.z());
  r.euler.pitch_rad = std::atan2(f.x(), std::hypot(f.y(), f.z()));
  // Resolve the body rate in the levelled (yaw-only) frame: w_l = Ry(pitch) Rx(roll) w_b
  //   = (W cos L cos(yaw), -W cos L sin(yaw), -W sin L).
  const Eigen::Matrix3d C_lb = (Eigen::AngleAxisd(r.euler.pitch_rad, Eigen::Vector3d::UnitY()) *
                                Eigen::AngleAxisd(r.euler.roll_rad, Eigen::Vector3d::UnitX()))
                                   .toRotationMatrix();
  const Eigen::Vector3d w_l = C_lb * w;
  r.euler.yaw_rad = std::atan2(-w_l.y(), w_l.x());
  r.q_nb = quaternion_from_euler(r.euler);
  return r;
}

AlignmentResult coarse_align(std::span<const ImuIncrement> imu, double t_start_s, double lat_rad) {
  if (imu.empty()) throw std::invalid_argument("coarse_align: no IMU data");
  Eigen::Vector3d sum_dtheta = Eigen::Vector3d::Zero(), sum_dv = Eigen::Vector3d::Zero();
  for (const auto& inc : imu) {
    sum_dtheta += inc.dtheta_b;
    sum_dv += inc.dv_b;
  }
  const double T = imu.back().t_s - t_start_s;
  if (!(T > 0.0)) throw std::invalid_argument("coarse_align: alignment span has no duration");
  AlignmentResult r = coarse_align(sum_dv / T, sum_dtheta / T, lat_rad);
  r.duration_s = T;
  return r;
}

Eigen::Vector3d alignment_error_from_biases(const Eigen::Vector3d& accel_bias_b, const Eigen::Vector3d& gyro_bias_b,
                                            const Eigen::Quaterniond& q_nb, double lat_rad, double g) {
  const Eigen::Vector3d b = q_nb * accel_bias_b;
  const Eigen::Vector3d eps = q_nb * gyro_bias_b;
  const double psi_n = b.y() / g;
  const double psi_e = -b.x() / g;
  const double psi_d = eps.y() / (kEarthRate_rps * std::cos(lat_rad)) - psi_n * std::tan(lat_rad);
  return {psi_n, psi_e, psi_d};
}

Eigen::Vector3d alignment_noise_sigma(const ImuErrorSpec& spec, double T, double lat_rad, double g) {
  auto mean_sigma = [T](const SensorErrorSpec& s) {
    return std::sqrt(s.random_walk * s.random_walk / T + 2.0 * s.output_white_noise * s.output_white_noise / (T * T));
  };
  const double tilt = mean_sigma(spec.accel) / g;
  const double heading_gyro = mean_sigma(spec.gyro) / (kEarthRate_rps * std::cos(lat_rad));
  const double heading_tilt = tilt * std::fabs(std::tan(lat_rad));
  return {tilt, tilt, std::hypot(heading_gyro, heading_tilt)};
}

}  // namespace ultratrack::ins

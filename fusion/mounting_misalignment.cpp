// SPDX-License-Identifier: GPL-3.0-or-later
#include "fusion/mounting_misalignment.hpp"

#include <stdexcept>

namespace ultratrack::fusion {

MountingEstimate estimate_mounting(std::span<const GnssAttitude> gps, const Eigen::Quaterniond& q_nb_ref,
                                   const Eigen::Matrix3d& P_ref_psi_n) {
  if (gps.empty()) throw std::invalid_argument("no GPS attitude to average");
  MountingEstimate m;
  m.samples = static_cast<int>(gps.size());
  // Mean rotation: rotation vectors (NED) of each attitude relative to the first, averaged, applied to the first.
  const Eigen::Quaterniond q0 = ins::quaternion_from_euler(gps.front().euler_a);
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  Eigen::Matrix3d P_gps = Eigen::Matrix3d::Zero();
  for (const auto& a : gps) {
    mean += ins::rotation_vector_from_quaternion(ins::quaternion_from_euler(a.euler_a) * q0.conjugate());
    const Eigen::Matrix3d M = euler_rate_to_rotation_n(a.euler_a);
    P_gps += M * a.sigma_euler_rad.cwiseAbs2().asDiagonal() * M.transpose();
  }
  const double n = m.samples;
  m.q_na_mean = (ins::quaternion_from_rotation_vector(mean / n) * q0).normalized();
  P_gps /= n * n;
  m.q_ba = (q_nb_ref.conjugate() * m.q_na_mean).normalized();
  m.angles = ins::euler_from_quaternion(m.q_ba);
  const Eigen::Matrix3d C_an = m.q_na_mean.toRotationMatrix().transpose();
  m.sigma_rad = (C_an * (P_ref_psi_n + P_gps) * C_an.transpose()).diagonal().cwiseMax(0.0).cwiseSqrt();
  return m;
}

}  // namespace ultratrack::fusion

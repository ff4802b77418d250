// SPDX-License-Identifier: GPL-3.0-or-later
#include "receiver/wahba_rotation.hpp"

#include <Eigen/LU>
#include <Eigen/SVD>

namespace ultratrack::receiver {

Eigen::Matrix3d wahba_rotation(const std::vector<Eigen::Vector3d>& l_body, const std::vector<Eigen::Vector3d>& v_ref,
                               const std::vector<double>& weights) {
  Eigen::Matrix3d B = Eigen::Matrix3d::Zero();
  for (std::size_t k = 0; k < l_body.size(); ++k) B += weights[k] * v_ref[k] * l_body[k].transpose();
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(B, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Matrix3d& U = svd.matrixU();
  const Eigen::Matrix3d& V = svd.matrixV();
  // The smallest singular direction takes the sign that makes det R = +1 (a reflection fits no rigid body).
  const Eigen::Vector3d d(1.0, 1.0, U.determinant() * V.determinant());
  return U * d.asDiagonal() * V.transpose();
}

}  // namespace ultratrack::receiver

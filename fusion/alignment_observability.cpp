// SPDX-License-Identifier: GPL-3.0-or-later
#include "fusion/alignment_observability.hpp"

#include <Eigen/SVD>
#include <cmath>

namespace ultratrack::fusion {

Eigen::MatrixXd alignment_observability_matrix(const ins::EulerAngles& e, const StationaryAlignmentModelOptions& model,
                                               const ObservabilityOptions& options) {
  const Eigen::Matrix3d C_nb = ins::quaternion_from_euler(e).toRotationMatrix();
  const AlignmentMatrix A = stationary_error_dynamics(C_nb, model);
  // H_G with its roll and yaw rows multiplied by cos(pitch): finite at any pitch.
  const double cg = std::cos(e.yaw_rad), sg = std::sin(e.yaw_rad);
  const double cb = std::cos(e.pitch_rad), sb = std::sin(e.pitch_rad);
  Eigen::Matrix3d HG;
  HG << -cg, -sg, 0.0,  //
      sg, -cg, 0.0,     //
      -sb * cg, -sb * sg, -cb;
  const int m = 3 * (options.zero_velocity ? 1 : 0) + 3 * (options.gps_attitude ? 1 : 0);
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(m, 12);
  int row = 0;
  if (options.zero_velocity) {
    H.block<3, 3>(row, align_ix::kVel).setIdentity();
    row += 3;
  }
  if (options.gps_attitude) H.block<3, 3>(row, align_ix::kAtt) = HG;
  Eigen::MatrixXd O(12 * m, 12);
  Eigen::MatrixXd block = H;
  for (int k = 0; k < 12; ++k) {
    const double scale = block.cwiseAbs().maxCoeff();
    O.middleRows(k * m, m) = scale > 0.0 ? Eigen::MatrixXd(block / scale) : block;
    block = block * A;
  }
  return O;
}

ObservabilityReport alignment_observability(const ins::EulerAngles& e, const StationaryAlignmentModelOptions& model,
                                            const ObservabilityOptions& options) {
  const Eigen::MatrixXd O = alignment_observability_matrix(e, model, options);
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(O, Eigen::ComputeFullV);
  ObservabilityReport r;
  r.singular_values = svd.singularValues();
  const double largest = r.singular_values(0);
  for (int i = 0; i < 12; ++i)
    if (r.singular_values(i) > options.rank_tolerance * largest) ++r.rank;
  r.weakest_direction = svd.matrixV().col(11);
  return r;
}

}  // namespace ultratrack::fusion

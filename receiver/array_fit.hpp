// SPDX-License-Identifier: GPL-3.0-or-later
// Attitude of a rigid antenna array from double differences with fixed integer ambiguities: each baseline's float
// (least-squares) vector, Wahba's SVD rotation of those baselines as the start, then Gauss-Newton on all DDs with
// their full covariance (the same estimator as the rotation fit weighted by the joint baseline covariance), giving
// the rotation R_eb (body -> ECEF), its small-rotation covariance and the DD residuals. Units: cycles, m, rad.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "receiver/phase_differences.hpp"

namespace ultratrack::receiver {

struct BaselineFloat {
  bool ok = false;  // at least 3 rows and a full-rank geometry
  Eigen::Vector3d b_e = Eigen::Vector3d::Zero();
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();  // m^2
  double residual_chi2 = 0.0;                            // rows - 3 degrees of freedom
};

struct ArrayFit {
  bool ok = false;
  Eigen::Matrix3d R_eb = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d covariance_e = Eigen::Matrix3d::Zero();  // small rotation about the ECEF axes, rad^2
  Eigen::VectorXd residual_cycles;
  double chi2 = 0.0;
  int dof = 0;
};

// Holds the weight (inverse DD covariance) of one epoch's DDs so that many integer candidates can be scored.
class ArrayFitter {
 public:
  // body_baselines[k]: lever arm of antenna k minus the master's, body frame, m ([0] unused).
  ArrayFitter(const DoubleDifferences& dd, std::vector<Eigen::Vector3d> body_baselines);

  // Least squares of antenna k's rows alone (its block of the covariance) with the given integers (all rows).
  BaselineFloat baseline_float(int antenna, const Eigen::VectorXd& integers) const;

  // The rigid fit with the given integers (all rows). initial_R_eb: a start near the answer (the previous epoch);
  // without one the start is Wahba's rotation of the baseline floats (needs two non-collinear determined baselines).
  ArrayFit fit(const Eigen::VectorXd& integers, const Eigen::Matrix3d* initial_R_eb = nullptr) const;

  const DoubleDifferences& dd() const { return *dd_; }

 private:
  const DoubleDifferences* dd_;
  std::vector<Eigen::Vector3d> body_;
  Eigen::MatrixXd weight_;                     // Q^-1
  std::vector<Eigen::MatrixXd> block_weight_;  // per antenna: (Q_kk)^-1
};

}  // namespace ultratrack::receiver

// SPDX-License-Identifier: GPL-3.0-or-later
#include "receiver/array_fit.hpp"

#include <Eigen/Cholesky>
#include <Eigen/LU>

#include "receiver/attitude_geometry.hpp"
#include "receiver/wahba_rotation.hpp"

namespace ultratrack::receiver {

namespace {

Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d S;
  S << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return S;
}

}  // namespace

ArrayFitter::ArrayFitter(const DoubleDifferences& dd, std::vector<Eigen::Vector3d> body_baselines)
    : dd_(&dd), body_(std::move(body_baselines)) {
  const auto m = dd.dd_cycles.size();
  weight_ = dd.covariance.ldlt().solve(Eigen::MatrixXd::Identity(m, m));
  block_weight_.resize(static_cast<std::size_t>(dd.num_antennas));
  for (int k = 1; k < dd.num_antennas; ++k) {
    const int b = dd.baseline_begin[static_cast<std::size_t>(k)];
    const int c = dd.baseline_count[static_cast<std::size_t>(k)];
    if (c == 0) continue;
    block_weight_[static_cast<std::size_t>(k)] =
        dd.covariance.block(b, b, c, c).ldlt().solve(Eigen::MatrixXd::Identity(c, c));
  }
}

BaselineFloat ArrayFitter::baseline_float(int antenna, const Eigen::VectorXd& integers) const {
  BaselineFloat out;
  const auto k = static_cast<std::size_t>(antenna);
  const int b = dd_->baseline_begin[k];
  const int c = dd_->baseline_count[k];
  if (c < 3) return out;
  const Eigen::MatrixXd G = dd_->geometry.middleRows(b, c);
  const Eigen::VectorXd y = dd_->dd_cycles.segment(b, c) - integers.segment(b, c);
  const Eigen::MatrixXd& W = block_weight_[k];
  const Eigen::Matrix3d N = G.transpose() * W * G;
  const Eigen::FullPivLU<Eigen::Matrix3d> lu(N);
  if (lu.rank() < 3) return out;
  out.covariance = lu.inverse();
  out.b_e = out.covariance * (G.transpose() * W * y);
  const Eigen::VectorXd r = y - G * out.b_e;
  out.residual_chi2 = r.dot(W * r);
  out.ok = true;
  return out;
}

ArrayFit ArrayFitter::fit(const Eigen::VectorXd& integers, const Eigen::Matrix3d* initial_R_eb) const {
  ArrayFit out;
  const auto m = static_cast<Eigen::Index>(dd_->rows.size());
  if (m < 4) return out;
  Eigen::Matrix3d R;
  if (initial_R_eb != nullptr) {
    R = *initial_R_eb;
  } else {
    std::vector<Eigen::Vector3d> l, v;
    std::vector<double> w;
    for (int k = 1; k < dd_->num_antennas; ++k) {
      const BaselineFloat f = baseline_float(k, integers);
      if (!f.ok) continue;
      l.push_back(body_[static_cast<std::size_t>(k)]);
      v.push_back(f.b_e);
      w.push_back(1.0 / f.covariance.trace());
    }
    if (l.size() < 2) return out;
    R = wahba_rotation(l, v, w);
  }
  const Eigen::VectorXd y = dd_->dd_cycles - integers;
  Eigen::VectorXd r(m);
  Eigen::MatrixXd J(m, 3);
  Eigen::Matrix3d N;
  for (int iter = 0; iter < 10; ++iter) {
    for (Eigen::Index i = 0; i < m; ++i) {
      const int k = dd_->rows[static_cast<std::size_t>(i)].antenna;
      const Eigen::Vector3d b = R * body_[static_cast<std::size_t>(k)];
      r(i) = y(i) - dd_->geometry.row(i).dot(b);
      J.row(i) = -dd_->geometry.row(i) * skew(b);
    }
    N = J.transpose() * weight_ * J;
    const Eigen::Vector3d delta = N.ldlt().solve(J.transpose() * (weight_ * r));
    R = rotation_from_vector(delta) * R;
    if (delta.norm() < 1e-10) break;
  }
  for (Eigen::Index i = 0; i < m; ++i) {
    const int k = dd_->rows[static_cast<std::size_t>(i)].antenna;
    const Eigen::Vector3d b = R * body_[static_cast<std::size_t>(k)];
    r(i) = y(i) - dd_->geometry.row(i).dot(b);
    J.row(i) = -dd_->geometry.row(i) * skew(b);
  }
  N = J.transpose() * weight_ * J;
  const Eigen::FullPivLU<Eigen::Matrix3d> lu(N);
  if (lu.rank() < 3) return out;
  out.ok = true;
  out.R_eb = R;
  out.covariance_e = lu.inverse();
  out.residual_cycles = r;
  out.chi2 = r.dot(weight_ * r);
  out.dof = static_cast<int>(m) - 3;
  return out;
}

}  // namespace ultratrack::receiver

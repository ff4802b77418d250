// SPDX-License-Identifier: GPL-3.0-or-later
// Seed 001 covariance analysis: the tight EKF's position 1-sigma is bracketed by two independent batch
// bounds built from the same satellite geometry (the single-epoch least-squares fix at that time above, the
// "frozen" vehicle that has all epochs measuring one constant position below), and the UKF equals the EKF on
// this (linear dynamics, almost linear range) model.
#include "fusion/covariance_analysis.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>

namespace {

using namespace ultratrack::fusion;

// Position covariance of a snapshot least-squares fix (position + clock bias, no prior).
Eigen::Matrix3d wls_position_covariance(const CovarianceSample& s, double sigma_m) {
  Eigen::MatrixXd H(s.los_ned.size(), 4);
  for (std::size_t i = 0; i < s.los_ned.size(); ++i) H.row(i) << -s.los_ned[i].transpose(), 1.0;
  const Eigen::Matrix4d info = H.transpose() * H / (sigma_m * sigma_m);
  return info.inverse().topLeftCorner<3, 3>();
}

// Every epoch up to t measuring one constant position, with clock bias + drift * t, from the eq. 38 priors
// (position 5, 5, sqrt 10 m; clock 10 m, 1 m/s). Knowing the velocity, attitude and bias errors to be zero
// can only add information, so this bounds the filter from below.
Eigen::Matrix3d frozen_position_covariance(const CovarianceAnalysisResult& r, double t, double sigma_m) {
  Eigen::Matrix<double, 5, 5> info = Eigen::Matrix<double, 5, 5>::Zero();
  info.diagonal() << 1.0 / 25.0, 1.0 / 25.0, 1.0 / 10.0, 1.0 / 100.0, 1.0;
  for (const auto& s : r.samples) {
    if (s.t_s > t + 1e-9 || s.los_ned.empty()) continue;
    for (const auto& u : s.los_ned) {
      Eigen::Matrix<double, 1, 5> h;
      h << -u.transpose(), 1.0, s.t_s;
      info += h.transpose() * h / (sigma_m * sigma_m);
    }
  }
  return info.inverse().topLeftCorner<3, 3>();
}

void check_bracket(const std::string& trajectory) {
  const auto r = run_covariance_analysis(seed001_covariance_options(trajectory, FilterKind::Ekf));
  for (double t : {30.0, 150.0}) {
    const CovarianceSample s = r.at(t);
    ASSERT_NEAR(s.t_s, t, 1e-6);
    ASSERT_GE(s.satellites, 5);
    const Eigen::Vector3d upper = wls_position_covariance(s, 5.0).diagonal().cwiseSqrt();
    const Eigen::Vector3d lower = frozen_position_covariance(r, t, 5.0).diagonal().cwiseSqrt();
    for (int i = 0; i < 3; ++i) {
      EXPECT_LE(s.sigma_pos_ned_m[i], upper[i]) << trajectory << " t " << t << " axis " << i;
      EXPECT_GE(s.sigma_pos_ned_m[i], lower[i]) << trajectory << " t " << t << " axis " << i;
    }
  }
}

TEST(CovarianceAnalysis, StraightEkfIsBracketedBySnapshotAndFrozenBounds) { check_bracket("straight"); }
TEST(CovarianceAnalysis, CircleEkfIsBracketedBySnapshotAndFrozenBounds) { check_bracket("circle"); }

// Linear error dynamics and a range that is linear to ~1e-6 over metres of error: the unscented transform is
// exact to that order, so the UKF's 1-sigma must match the EKF's closely on every trajectory.
TEST(CovarianceAnalysis, UkfMatchesEkfOnTheSeedTrajectories) {
  for (const char* name : {"straight", "circle", "s", "spiral"}) {
    auto o = seed001_covariance_options(name, FilterKind::Ekf);
    o.duration_s = 60.0;
    const auto ekf = run_covariance_analysis(o);
    o.filter = FilterKind::Ukf;
    const auto ukf = run_covariance_analysis(o);
    ASSERT_EQ(ekf.samples.size(), ukf.samples.size());
    for (double t : {1.0, 10.0, 30.0, 60.0})
      for (int i = 0; i < 3; ++i)
        EXPECT_NEAR(ukf.at(t).sigma_pos_ned_m[i] / ekf.at(t).sigma_pos_ned_m[i], 1.0, 1e-3) << name << " t " << t;
  }
}

TEST(CovarianceAnalysis, UnknownTrajectoryIsAnInputError) {
  EXPECT_ANY_THROW(run_covariance_analysis(seed001_covariance_options("zigzag", FilterKind::Ekf)));
}

}  // namespace

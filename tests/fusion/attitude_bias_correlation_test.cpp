// SPDX-License-Identifier: GPL-3.0-or-later
// The initial covariance of an attitude that errs with the biases, against a Monte Carlo of psi = J b + e.
#include "fusion/attitude_bias_correlation.hpp"

#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <cmath>
#include <random>

namespace {

using namespace ultratrack::fusion;

TEST(AttitudeBiasCorrelation, MatchesTheSampleCovarianceOfCorrelatedDraws) {
  std::mt19937_64 rng(5);
  std::normal_distribution<double> n(0.0, 1.0);
  // Biases with some correlation between them, an independent attitude part, and a J of levelling's size.
  Eigen::Matrix<double, 6, 6> M;
  for (int i = 0; i < 36; ++i) M(i) = n(rng);
  const Eigen::Matrix<double, 6, 6> P_bb = 0.05 * M * M.transpose() + 0.01 * Eigen::Matrix<double, 6, 6>::Identity();
  const Eigen::Vector3d sigma_e(0.003, 0.004, 0.01);
  AttitudePerBias J;
  for (int i = 0; i < 18; ++i) J(i) = 0.1 * n(rng);
  StateMatrix<15> P = StateMatrix<15>::Zero();
  P.diagonal().head<6>().setConstant(4.0);  // position, velocity: untouched
  P.block<3, 3>(ix::kAtt, ix::kAtt) = sigma_e.cwiseAbs2().asDiagonal();
  P.block<6, 6>(ix::kAccelBias, ix::kAccelBias) = P_bb;
  const StateMatrix<15> before = P;
  correlate_attitude_with_biases<15>(P, J);

  const Eigen::Matrix<double, 6, 6> L = P_bb.llt().matrixL();
  const int draws = 200000;
  Eigen::Matrix<double, 9, 9> S = Eigen::Matrix<double, 9, 9>::Zero();  // [psi; b]
  for (int k = 0; k < draws; ++k) {
    Eigen::Matrix<double, 6, 1> z;
    for (int i = 0; i < 6; ++i) z(i) = n(rng);
    const Eigen::Matrix<double, 6, 1> b = L * z;
    const Eigen::Vector3d e(sigma_e.x() * n(rng), sigma_e.y() * n(rng), sigma_e.z() * n(rng));
    Eigen::Matrix<double, 9, 1> x;
    x << J * b + e, b;
    S += x * x.transpose();
  }
  S /= draws;
  const Eigen::Matrix<double, 9, 9> got = P.block<9, 9>(ix::kAtt, ix::kAtt);
  for (int i = 0; i < 9; ++i)
    for (int j = 0; j < 9; ++j) {  // standard error of a sample covariance: sqrt((S_ii S_jj + S_ij^2) / n)
      const double se = std::sqrt((got(i, i) * got(j, j) + got(i, j) * got(i, j)) / draws);
      EXPECT_NEAR(got(i, j), S(i, j), 5.0 * se) << i << "," << j;
    }
  EXPECT_TRUE((P.topLeftCorner<6, 6>().array() == before.topLeftCorner<6, 6>().array()).all());
  EXPECT_TRUE((P.block<6, 6>(ix::kAccelBias, ix::kAccelBias).array() == P_bb.array()).all());
}

}  // namespace

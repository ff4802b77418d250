// SPDX-License-Identifier: GPL-3.0-or-later
// The bias covariance across an attitude correction (fusion/bias_frame_reset.hpp): what the filter knows about the
// biases in the nav frame, C_nb b, must be the same before the correction (through C_old) and after it (through
// C_new); states other than the biases keep their covariance.
#include "fusion/bias_frame_reset.hpp"

#include <gtest/gtest.h>

#include <random>

namespace {

using namespace ultratrack::fusion;

StateMatrix<17> random_covariance(std::mt19937_64& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  StateMatrix<17> M;
  for (int i = 0; i < 17 * 17; ++i) M(i) = n(rng);
  return M * M.transpose() + 0.1 * StateMatrix<17>::Identity();
}

// The nav-frame view of the bias states: x_nav = [other states; C b_a; C b_g] = S(C) x.
StateMatrix<17> nav_view(const Eigen::Matrix3d& C) {
  StateMatrix<17> S = StateMatrix<17>::Identity();
  S.block<3, 3>(ix::kAccelBias, ix::kAccelBias) = C;
  S.block<3, 3>(ix::kGyroBias, ix::kGyroBias) = C;
  return S;
}

TEST(BiasFrameReset, KeepsTheNavFrameCovarianceOfTheBiasesAndTheirCrossTerms) {
  std::mt19937_64 rng(11);
  const StateMatrix<17> P = random_covariance(rng);
  const Eigen::Quaterniond q_old(Eigen::AngleAxisd(0.7, Eigen::Vector3d(0.2, -0.5, 1.0).normalized()));
  // A correction of several degrees, as an MEMS unit's first updates make.
  const Eigen::Quaterniond q_new =
      Eigen::Quaterniond(Eigen::AngleAxisd(0.08, Eigen::Vector3d(1.0, 0.3, -0.2).normalized())) * q_old;
  const StateMatrix<17> P_new = reset_bias_frame<17>(P, q_old, q_new);
  const StateMatrix<17> before =
      nav_view(q_old.toRotationMatrix()) * P * nav_view(q_old.toRotationMatrix()).transpose();
  const StateMatrix<17> after =
      nav_view(q_new.toRotationMatrix()) * P_new * nav_view(q_new.toRotationMatrix()).transpose();
  EXPECT_LT((after - before).cwiseAbs().maxCoeff(), 1e-12 * P.cwiseAbs().maxCoeff());
  // The body-frame bias covariance itself did turn (the check above is not trivially met).
  EXPECT_GT((P_new.block<6, 6>(ix::kAccelBias, ix::kAccelBias) - P.block<6, 6>(ix::kAccelBias, ix::kAccelBias))
                .cwiseAbs()
                .maxCoeff(),
            1e-3);
  // Position, velocity, attitude and clock among themselves: untouched.
  EXPECT_TRUE((P_new.topLeftCorner<9, 9>() == P.topLeftCorner<9, 9>()));
  EXPECT_TRUE((P_new.bottomRightCorner<2, 2>() == P.bottomRightCorner<2, 2>()));
  EXPECT_TRUE(P_new.isApprox(P_new.transpose(), 0.0));
}

TEST(BiasFrameReset, IsTheIdentityWithoutAnAttitudeCorrection) {
  std::mt19937_64 rng(12);
  const StateMatrix<17> P = random_covariance(rng);
  const Eigen::Quaterniond q(Eigen::AngleAxisd(-1.2, Eigen::Vector3d(0.4, 0.1, 0.9).normalized()));
  EXPECT_LT((reset_bias_frame<17>(P, q, q) - P).cwiseAbs().maxCoeff(), 1e-14 * P.cwiseAbs().maxCoeff());
}

}  // namespace

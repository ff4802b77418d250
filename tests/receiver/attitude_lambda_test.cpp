// SPDX-License-Identifier: GPL-3.0-or-later
// LAMBDA against brute-force enumeration (independent truth) on random small integer least-squares problems, and
// the algebra of its factorisation and decorrelation; chi-square quantiles against published table values.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <cmath>
#include <random>

#include "receiver/chi_square.hpp"
#include "receiver/lambda.hpp"

using namespace ultratrack::receiver;

namespace {

// A random SPD matrix with strong correlations (as float ambiguities have): A A^T + small diagonal, scaled.
Eigen::MatrixXd random_covariance(int n, std::mt19937_64& rng) {
  std::normal_distribution<double> g(0.0, 1.0);
  std::uniform_real_distribution<double> u(0.05, 3.0);
  Eigen::MatrixXd A(n, n);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) A(i, j) = g(rng);
  }
  Eigen::MatrixXd Q = A * A.transpose() * u(rng);
  for (int i = 0; i < n; ++i) Q(i, i) += 0.01;
  return Q;
}

double metric(const Eigen::VectorXd& a, const Eigen::MatrixXd& Qinv, const Eigen::VectorXd& z) {
  const Eigen::VectorXd d = a - z;
  return d.dot(Qinv * d);
}

// All integer vectors in the box that must contain every candidate with metric <= bound:
// |a_i - z_i| <= sqrt(bound * Q_ii).
std::vector<std::pair<double, Eigen::VectorXd>> brute_force(const Eigen::VectorXd& a, const Eigen::MatrixXd& Q,
                                                            double bound) {
  const int n = static_cast<int>(a.size());
  const Eigen::MatrixXd Qinv = Q.inverse();
  std::vector<long> lo(n), hi(n), z(n);
  for (int i = 0; i < n; ++i) {
    const double r = std::sqrt(bound * Q(i, i));
    lo[i] = static_cast<long>(std::ceil(a(i) - r));
    hi[i] = static_cast<long>(std::floor(a(i) + r));
    z[i] = lo[i];
  }
  std::vector<std::pair<double, Eigen::VectorXd>> out;
  for (;;) {
    Eigen::VectorXd v(n);
    for (int i = 0; i < n; ++i) v(i) = static_cast<double>(z[i]);
    const double m = metric(a, Qinv, v);
    if (m <= bound) out.push_back({m, v});
    int i = 0;
    while (i < n && ++z[i] > hi[i]) z[i] = lo[i], ++i;
    if (i == n) break;
  }
  std::sort(out.begin(), out.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
  return out;
}

}  // namespace

TEST(AttitudeLambda, LtdlReconstructsTheMatrix) {
  std::mt19937_64 rng(1);
  for (int n = 1; n <= 8; ++n) {
    const Eigen::MatrixXd Q = random_covariance(n, rng);
    const LtdlFactor f = ltdl_decompose(Q);
    EXPECT_LT((f.L.transpose() * f.D.asDiagonal() * f.L - Q).norm(), 1e-9 * Q.norm());
    for (int i = 0; i < n; ++i) {
      EXPECT_DOUBLE_EQ(f.L(i, i), 1.0);
      for (int j = i + 1; j < n; ++j) EXPECT_EQ(f.L(i, j), 0.0);
    }
  }
  EXPECT_THROW(ltdl_decompose(Eigen::MatrixXd::Zero(2, 2)), std::invalid_argument);
}

TEST(AttitudeLambda, ReductionIsUnimodularAndDecorrelates) {
  std::mt19937_64 rng(2);
  for (int trial = 0; trial < 200; ++trial) {
    const int n = 2 + trial % 7;
    const Eigen::MatrixXd Q = random_covariance(n, rng);
    const LambdaReduction r = lambda_reduce(Q);
    EXPECT_NEAR(std::abs(r.Z.determinant()), 1.0, 1e-9);
    EXPECT_LT((r.Z - r.Z.array().round().matrix()).norm(), 1e-12);
    const Eigen::MatrixXd Qz = r.Z.transpose() * Q * r.Z;
    EXPECT_LT((r.factor.L.transpose() * r.factor.D.asDiagonal() * r.factor.L - Qz).norm(), 1e-8 * Qz.norm());
    for (int i = 0; i < n; ++i) {
      for (int j = 0; j < i; ++j) EXPECT_LE(std::abs(r.factor.L(i, j)), 0.5 + 1e-9);
    }
    // Decorrelation shrinks the product of the diagonal variances towards det Q (the volume is invariant).
    EXPECT_LE(Qz.diagonal().prod(), Q.diagonal().prod() * (1.0 + 1e-9));
    EXPECT_NEAR(Qz.determinant() / Q.determinant(), 1.0, 1e-6);
  }
}

TEST(AttitudeLambda, BestTwoMatchBruteForce) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-50.0, 50.0);
  for (int trial = 0; trial < 400; ++trial) {
    const int n = 1 + trial % 4;
    const Eigen::MatrixXd Q = random_covariance(n, rng);
    Eigen::VectorXd a(n);
    for (int i = 0; i < n; ++i) a(i) = u(rng);
    const std::vector<IntegerCandidate> c = lambda_search(a, Q, 2);
    ASSERT_EQ(c.size(), 2u);
    // The second candidate's metric bounds the box that holds both.
    const auto bf = brute_force(a, Q, c[1].squared_norm * (1.0 + 1e-9) + 1e-9);
    ASSERT_GE(bf.size(), 2u);
    EXPECT_NEAR(c[0].squared_norm, bf[0].first, 1e-7 * (1.0 + bf[0].first));
    EXPECT_NEAR(c[1].squared_norm, bf[1].first, 1e-7 * (1.0 + bf[1].first));
    EXPECT_LT((c[0].a - bf[0].second).norm(), 1e-9) << trial;
    EXPECT_NEAR(metric(a, Q.inverse(), c[0].a), c[0].squared_norm, 1e-7 * (1.0 + c[0].squared_norm));
  }
}

TEST(AttitudeLambda, EnumeratesTheWholeEllipsoid) {
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> u(-5.0, 5.0), b(2.0, 12.0);
  for (int trial = 0; trial < 100; ++trial) {
    const int n = 2 + trial % 3;
    const Eigen::MatrixXd Q = random_covariance(n, rng);
    Eigen::VectorXd a(n);
    for (int i = 0; i < n; ++i) a(i) = u(rng);
    const double bound = b(rng);
    const auto bf = brute_force(a, Q, bound);
    const std::vector<IntegerCandidate> c = lambda_search(a, Q, 100000, bound);
    ASSERT_EQ(c.size(), bf.size()) << trial;
    for (std::size_t i = 0; i < c.size(); ++i) EXPECT_NEAR(c[i].squared_norm, bf[i].first, 1e-7);
    // With a cap, the best `cap` are kept.
    if (bf.size() > 3) {
      const std::vector<IntegerCandidate> c3 = lambda_search(a, Q, 3, bound);
      ASSERT_EQ(c3.size(), 3u);
      for (int i = 0; i < 3; ++i)
        EXPECT_NEAR(c3[static_cast<std::size_t>(i)].squared_norm, bf[static_cast<std::size_t>(i)].first, 1e-7);
    }
  }
}

TEST(AttitudeLambda, ChiSquareQuantilesMatchTables) {
  // NIST/SEMATECH e-Handbook, table of upper critical values of the chi-square distribution.
  // Published table values (3 decimals: within 0.0005 of the exact quantile).
  EXPECT_NEAR(chi_square_upper_quantile(1, 0.05), 3.841, 0.0005);
  EXPECT_NEAR(chi_square_upper_quantile(2, 0.01), 9.210, 0.0005);
  EXPECT_NEAR(chi_square_upper_quantile(3, 0.05), 7.815, 0.0005);
  EXPECT_NEAR(chi_square_upper_quantile(10, 0.01), 23.209, 0.0005);
  EXPECT_NEAR(chi_square_upper_quantile(20, 0.001), 45.315, 0.0005);
  EXPECT_NEAR(chi_square_upper_tail(2, -2.0 * std::log(1e-12)), 1e-12, 1e-20);  // closed form for 2 dof, deep tail
  EXPECT_NEAR(chi_square_lower_quantile(5, 0.3), chi_square_upper_quantile(5, 0.7), 1e-9);
  EXPECT_NEAR(normal_upper_quantile(0.025), 1.959964, 1e-5);
}

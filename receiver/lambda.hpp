// SPDX-License-Identifier: GPL-3.0-or-later
// Integer least squares by the LAMBDA method (Teunissen 1995; de Jonge & Tiberius 1996): L^T D L decomposition of
// the float ambiguity covariance, decorrelation by integer Gauss transformations and permutations (Z, |det Z| = 1),
// then a depth-first search of the decorrelated ellipsoid with zig-zag enumeration that shrinks as the best
// candidates are found (the search order of Chang, Yang & Zhou 2005, MLAMBDA). Units: cycles, cycles^2.
#pragma once

#include <Eigen/Core>
#include <limits>
#include <vector>

namespace ultratrack::receiver {

// Q = L^T diag(D) L with L unit lower triangular (the factorisation LAMBDA uses: conditional variances D from the
// last ambiguity down to the first). Q must be symmetric positive definite.
struct LtdlFactor {
  Eigen::MatrixXd L;
  Eigen::VectorXd D;
};
LtdlFactor ltdl_decompose(const Eigen::MatrixXd& Q);

// Decorrelating transformation: z = Z^T a has covariance Z^T Q Z = L^T diag(D) L (the returned factor), with Z
// integer and unimodular, |L(i,j)| <= 1/2 below the diagonal and D ordered as far as the permutations could.
struct LambdaReduction {
  Eigen::MatrixXd Z;  // integer-valued
  LtdlFactor factor;  // of Z^T Q Z
};
LambdaReduction lambda_reduce(const Eigen::MatrixXd& Q);

struct IntegerCandidate {
  Eigen::VectorXd a;          // integer-valued, in the original (not decorrelated) ambiguities
  double squared_norm = 0.0;  // (a_float - a)^T Q^-1 (a_float - a)
};

// The `count` integer vectors nearest to a_float in the metric of Q (best first) among those with squared norm
// below `chi2_bound`: count = 2 gives the ILS solution and the runner-up for the ratio test; a finite bound with a
// large count enumerates the whole ellipsoid (when more than count lie inside, the best count are kept).
std::vector<IntegerCandidate> lambda_search(const Eigen::VectorXd& a_float, const Eigen::MatrixXd& Q, int count,
                                            double chi2_bound = std::numeric_limits<double>::infinity());

}  // namespace ultratrack::receiver

// SPDX-License-Identifier: GPL-3.0-or-later
#include "receiver/lambda.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace ultratrack::receiver {

LtdlFactor ltdl_decompose(const Eigen::MatrixXd& Q) {
  const Eigen::Index n = Q.rows();
  Eigen::MatrixXd A = Q;
  LtdlFactor f{Eigen::MatrixXd::Zero(n, n), Eigen::VectorXd::Zero(n)};
  for (Eigen::Index i = n - 1; i >= 0; --i) {
    f.D(i) = A(i, i);
    if (!(f.D(i) > 0.0)) throw std::invalid_argument("ltdl_decompose: matrix not positive definite");
    const double s = std::sqrt(A(i, i));
    for (Eigen::Index j = 0; j <= i; ++j) f.L(i, j) = A(i, j) / s;
    for (Eigen::Index j = 0; j < i; ++j) {
      for (Eigen::Index k = 0; k <= j; ++k) A(j, k) -= f.L(i, k) * f.L(i, j);
    }
    for (Eigen::Index j = 0; j <= i; ++j) f.L(i, j) /= f.L(i, i);
  }
  return f;
}

namespace {

// Integer Gauss transformation: makes |L(i,j)| <= 1/2 (i > j), Z follows.
void gauss_transform(Eigen::MatrixXd& L, Eigen::MatrixXd& Z, Eigen::Index i, Eigen::Index j) {
  const double mu = std::round(L(i, j));
  if (mu == 0.0) return;
  for (Eigen::Index k = i; k < L.rows(); ++k) L(k, j) -= mu * L(k, i);
  Z.col(j) -= mu * Z.col(i);
}

// Swaps ambiguities j and j+1 when that lowers D(j+1) (del is the new D(j+1)).
void permute(Eigen::MatrixXd& L, Eigen::VectorXd& D, Eigen::MatrixXd& Z, Eigen::Index j, double del) {
  const double eta = D(j) / del;
  const double lam = D(j + 1) * L(j + 1, j) / del;
  D(j) = eta * D(j + 1);
  D(j + 1) = del;
  for (Eigen::Index k = 0; k < j; ++k) {
    const double a0 = L(j, k);
    const double a1 = L(j + 1, k);
    L(j, k) = -L(j + 1, j) * a0 + a1;
    L(j + 1, k) = eta * a0 + lam * a1;
  }
  L(j + 1, j) = lam;
  for (Eigen::Index k = j + 2; k < L.rows(); ++k) std::swap(L(k, j), L(k, j + 1));
  Z.col(j).swap(Z.col(j + 1));
}

}  // namespace

LambdaReduction lambda_reduce(const Eigen::MatrixXd& Q) {
  const Eigen::Index n = Q.rows();
  LambdaReduction r{Eigen::MatrixXd::Identity(n, n), ltdl_decompose(Q)};
  Eigen::MatrixXd& L = r.factor.L;
  Eigen::VectorXd& D = r.factor.D;
  Eigen::Index j = n - 2;
  Eigen::Index k = n - 2;
  while (j >= 0) {
    if (j <= k) {
      for (Eigen::Index i = j + 1; i < n; ++i) gauss_transform(L, r.Z, i, j);
    }
    const double del = D(j) + L(j + 1, j) * L(j + 1, j) * D(j + 1);
    if (del + 1e-9 * D(j + 1) < D(j + 1)) {
      permute(L, D, r.Z, j, del);
      k = j;
      j = n - 2;
    } else {
      --j;
    }
  }
  return r;
}

std::vector<IntegerCandidate> lambda_search(const Eigen::VectorXd& a_float, const Eigen::MatrixXd& Q, int count,
                                            double chi2_bound) {
  const Eigen::Index n = a_float.size();
  std::vector<IntegerCandidate> out;
  if (n == 0 || count <= 0) return out;
  const LambdaReduction red = lambda_reduce(Q);
  const Eigen::MatrixXd& L = red.factor.L;
  const Eigen::VectorXd& D = red.factor.D;
  // Shift by the integer part first so that the search works near zero (no loss of precision for large values).
  const Eigen::VectorXd a_int = a_float.array().round().matrix();
  const Eigen::VectorXd zf = red.Z.transpose() * (a_float - a_int);

  std::vector<Eigen::VectorXd> found_z;
  std::vector<double> found_dist;
  double max_dist = chi2_bound;
  Eigen::VectorXd z(n), zb(n), e(n), dist(n), step(n);
  auto sign = [](double v) { return v <= 0.0 ? -1.0 : 1.0; };

  Eigen::Index k = n - 1;
  dist(k) = 0.0;
  zb(k) = zf(k);
  z(k) = std::round(zb(k));
  step(k) = sign(zb(k) - z(k));
  for (;;) {
    const double ek = zb(k) - z(k);
    const double new_dist = dist(k) + ek * ek / D(k);
    if (new_dist < max_dist) {
      if (k != 0) {
        e(k) = ek;
        --k;
        dist(k) = new_dist;
        double s = zf(k);
        for (Eigen::Index j = k + 1; j < n; ++j) s -= L(j, k) * e(j);
        zb(k) = s;
        z(k) = std::round(zb(k));
        step(k) = sign(zb(k) - z(k));
      } else {
        if (static_cast<int>(found_z.size()) < count) {
          found_z.push_back(z);
          found_dist.push_back(new_dist);
          if (static_cast<int>(found_z.size()) == count) {
            max_dist = *std::max_element(found_dist.begin(), found_dist.end());
          }
        } else {
          const auto worst = std::max_element(found_dist.begin(), found_dist.end()) - found_dist.begin();
          found_z[static_cast<std::size_t>(worst)] = z;
          found_dist[static_cast<std::size_t>(worst)] = new_dist;
          max_dist = *std::max_element(found_dist.begin(), found_dist.end());
        }
        z(0) += step(0);
        step(0) = -step(0) - sign(step(0));
      }
    } else {
      if (k == n - 1) break;
      ++k;
      z(k) += step(k);
      step(k) = -step(k) - sign(step(k));
    }
  }

  const Eigen::MatrixXd Z_inv_T = red.Z.transpose().fullPivLu().inverse().array().round().matrix();
  std::vector<std::size_t> order(found_z.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return found_dist[a] < found_dist[b]; });
  out.reserve(order.size());
  for (std::size_t i : order) {
    out.push_back({(Z_inv_T * found_z[i] + a_int).array().round().matrix(), found_dist[i]});
  }
  return out;
}

}  // namespace ultratrack::receiver

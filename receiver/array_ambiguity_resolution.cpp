// SPDX-License-Identifier: GPL-3.0-or-later
#include "receiver/array_ambiguity_resolution.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>

#include "receiver/chi_square.hpp"
#include "receiver/lambda.hpp"

namespace ultratrack::receiver {

namespace {

struct Kept {
  Eigen::VectorXd a;  // this baseline's rows
  BaselineFloat f;
};

struct BaselineSet {
  int antenna = 0;
  int begin = 0, count = 0;
  std::vector<Kept> kept;
};

// LAMBDA candidates of one baseline that pass the residual and length gates.
BaselineSet constrained_candidates(const ArrayFitter& fitter, int k, double length_m,
                                   const AmbiguityResolutionOptions& o, AmbiguityResolution& stats) {
  const DoubleDifferences& dd = fitter.dd();
  BaselineSet set;
  set.antenna = k;
  set.begin = dd.baseline_begin[static_cast<std::size_t>(k)];
  set.count = dd.baseline_count[static_cast<std::size_t>(k)];
  const int dof = set.count - 3;
  const Eigen::MatrixXd G = dd.geometry.middleRows(set.begin, set.count);
  const Eigen::MatrixXd Q = dd.covariance.block(set.begin, set.begin, set.count, set.count);
  const Eigen::VectorXd y = dd.dd_cycles.segment(set.begin, set.count);
  const double p_gate = std::erfc(o.gate_sigma / std::sqrt(2.0));  // two-sided normal tail of the gate
  const double q = chi_square_upper_quantile(dof, p_gate);
  // Prior weight that minimises the enumerated volume (3 geometry dimensions against dof noise dimensions).
  const double alpha2 = 3.0 * q / dof;
  const double sigma_b = length_m / std::sqrt(alpha2);
  const Eigen::Matrix3d Qb_nominal = (G.transpose() * Q.ldlt().solve(G)).inverse();
  const double sigma_len_max = std::sqrt(Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(Qb_nominal).eigenvalues()(2));
  const double l_max = length_m + o.length_tolerance_m + o.gate_sigma * sigma_len_max;
  const double bound = q + alpha2 * (l_max / length_m) * (l_max / length_m);
  const Eigen::MatrixXd Qa = Q + sigma_b * sigma_b * G * G.transpose();
  const std::vector<IntegerCandidate> cands = lambda_search(y, Qa, o.max_candidates_per_baseline, bound);
  stats.candidates_enumerated += static_cast<int>(cands.size());
  if (static_cast<int>(cands.size()) >= o.max_candidates_per_baseline) stats.truncated = true;
  Eigen::VectorXd all = Eigen::VectorXd::Zero(dd.dd_cycles.size());
  for (const IntegerCandidate& c : cands) {
    all.segment(set.begin, set.count) = c.a;
    const BaselineFloat f = fitter.baseline_float(k, all);
    if (!f.ok || f.residual_chi2 > q) continue;
    const double len = f.b_e.norm();
    const Eigen::Vector3d u = f.b_e / len;
    const double sigma_len = std::sqrt(u.dot(f.covariance * u));
    if (std::abs(len - length_m) > o.gate_sigma * sigma_len + o.length_tolerance_m) continue;
    set.kept.push_back({c.a, f});
  }
  stats.candidates_kept += static_cast<int>(set.kept.size());
  return set;
}

struct Search {
  const ArrayFitter* fitter = nullptr;
  const std::vector<Eigen::Vector3d>* body = nullptr;
  const AmbiguityResolutionOptions* o = nullptr;
  std::vector<BaselineSet> sets;
  std::vector<std::size_t> choice;
  Eigen::VectorXd integers;
  double best = std::numeric_limits<double>::infinity(), second = std::numeric_limits<double>::infinity();
  Eigen::VectorXd best_integers;
  ArrayFit best_fit;
  std::vector<ArrayCandidate> all;  // every rigid candidate with a fit

  bool distances_consistent(std::size_t level) const {
    const Kept& a = sets[level].kept[choice[level]];
    const Eigen::Vector3d& la = (*body)[static_cast<std::size_t>(sets[level].antenna)];
    for (std::size_t j = 0; j < level; ++j) {
      const Kept& b = sets[j].kept[choice[j]];
      const Eigen::Vector3d& lb = (*body)[static_cast<std::size_t>(sets[j].antenna)];
      const Eigen::Vector3d d = a.f.b_e - b.f.b_e;
      const double len = d.norm();
      const Eigen::Vector3d u = d / len;
      const double sigma = std::sqrt(u.dot((a.f.covariance + b.f.covariance) * u));
      if (std::abs(len - (la - lb).norm()) > o->gate_sigma * sigma + 2.0 * o->length_tolerance_m) return false;
    }
    return true;
  }

  void recurse(std::size_t level) {
    if (level == sets.size()) {
      const ArrayFit fit = fitter->fit(integers);
      if (!fit.ok) return;
      all.push_back({integers, fit.chi2});
      if (fit.chi2 < best) {
        second = best;
        best = fit.chi2;
        best_integers = integers;
        best_fit = fit;
      } else if (fit.chi2 < second) {
        second = fit.chi2;
      }
      return;
    }
    for (std::size_t i = 0; i < sets[level].kept.size(); ++i) {
      choice[level] = i;
      if (!distances_consistent(level)) continue;
      integers.segment(sets[level].begin, sets[level].count) = sets[level].kept[i].a;
      recurse(level + 1);
    }
  }
};

}  // namespace

AmbiguityResolution resolve_array_ambiguities(const ArrayFitter& fitter,
                                              const std::vector<Eigen::Vector3d>& body_baselines,
                                              const AmbiguityResolutionOptions& o) {
  AmbiguityResolution out;
  const DoubleDifferences& dd = fitter.dd();
  out.integers = Eigen::VectorXd::Zero(dd.dd_cycles.size());
  std::vector<int> antennas;
  for (int k = 1; k < dd.num_antennas; ++k) {
    const int c = dd.baseline_count[static_cast<std::size_t>(k)];
    if (c == 0) continue;
    if (c < 4) return out;
    antennas.push_back(k);
  }
  if (antennas.size() < 2) return out;

  if (!o.use_constraints) {
    double min_ratio = std::numeric_limits<double>::infinity();
    for (int k : antennas) {
      const int b = dd.baseline_begin[static_cast<std::size_t>(k)];
      const int c = dd.baseline_count[static_cast<std::size_t>(k)];
      const Eigen::MatrixXd G = dd.geometry.middleRows(b, c);
      const double sigma_b = body_baselines[static_cast<std::size_t>(k)].norm();
      const Eigen::MatrixXd Qa = dd.covariance.block(b, b, c, c) + sigma_b * sigma_b * G * G.transpose();
      const std::vector<IntegerCandidate> best2 = lambda_search(dd.dd_cycles.segment(b, c), Qa, 2);
      out.candidates_enumerated += static_cast<int>(best2.size());
      out.integers.segment(b, c) = best2.front().a;
      const double r =
          best2.size() > 1 ? best2[1].squared_norm / best2[0].squared_norm : std::numeric_limits<double>::infinity();
      min_ratio = std::min(min_ratio, r);
    }
    out.fit = fitter.fit(out.integers);
    out.ratio = min_ratio;
    out.fixed = out.fit.ok && out.ratio >= o.ratio_threshold;
    return out;
  }

  Search s;
  s.fitter = &fitter;
  s.body = &body_baselines;
  s.o = &o;
  s.integers = out.integers;
  for (int k : antennas) {
    s.sets.push_back(constrained_candidates(fitter, k, body_baselines[static_cast<std::size_t>(k)].norm(), o, out));
    if (s.sets.back().kept.empty()) return out;
  }
  s.choice.assign(s.sets.size(), 0);
  s.recurse(0);
  if (!std::isfinite(s.best)) return out;
  out.integers = s.best_integers;
  out.fit = s.best_fit;
  out.ratio = s.second / std::max(s.best, 1e-12);
  out.difference = s.second - s.best;
  std::sort(s.all.begin(), s.all.end(), [](const auto& a, const auto& b) { return a.chi2 < b.chi2; });
  for (const ArrayCandidate& c : s.all) {
    if (c.chi2 > s.best + o.keep_margin) break;
    if (static_cast<int>(out.candidates.size()) == o.max_kept) {
      out.kept_truncated = true;
      break;
    }
    out.candidates.push_back(c);
  }
  const double chi2_max = chi_square_upper_quantile(std::max(out.fit.dof, 1), o.residual_test_pfa);
  out.fixed = out.fit.ok && out.fit.chi2 <= chi2_max && out.ratio >= o.ratio_threshold &&
              out.difference >= o.difference_threshold;
  return out;
}

}  // namespace ultratrack::receiver

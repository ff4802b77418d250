// SPDX-License-Identifier: GPL-3.0-or-later
#include "receiver/attitude_solver.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <set>
#include <stdexcept>

#include "io/why_invalid.hpp"
#include "receiver/array_ambiguity_resolution.hpp"
#include "receiver/array_fit.hpp"
#include "receiver/attitude_geometry.hpp"
#include "receiver/chi_square.hpp"
#include "receiver/phase_differences.hpp"
#include "receiver/wahba_rotation.hpp"
#include "signals/gps_constants.hpp"

namespace ultratrack::receiver {

bool AttitudeSolverOptions::IsValid(std::string* why) const {
  const AttitudeSolverOptions& o = *this;
  const std::string problem = [&]() -> std::string {
    const auto& lever = o.array.lever_arm_body_m;
    if (lever.size() < 3 || lever.size() > static_cast<std::size_t>(kMaxAntennas)) {
      return "the antenna array needs 3 to " + std::to_string(kMaxAntennas) + " antennas";
    }
    bool two_directions = false;
    for (std::size_t k = 1; k < lever.size(); ++k) {
      const Eigen::Vector3d bk = lever[k] - lever[0];
      if (!bk.allFinite() || bk.norm() < 0.1)
        return "antenna " + std::to_string(k) + " is less than 0.1 m from the master";
      for (std::size_t j = 1; j < k; ++j) {
        const Eigen::Vector3d bj = lever[j] - lever[0];
        if (bj.cross(bk).norm() > 0.1 * bj.norm() * bk.norm()) two_directions = true;
      }
    }
    if (!two_directions) return "the baselines are collinear: no full attitude";
    if (!(o.phase_sigma_m > 0.0 && o.phase_sigma_m < 0.05)) return "phase_sigma_m must be in (0, 0.05) m";
    if (!(o.elevation_mask_rad >= 0.0 && o.elevation_mask_rad < std::numbers::pi / 2)) {
      return "elevation_mask_rad must be in [0, pi/2)";
    }
    if (o.min_satellites < 5) return "min_satellites must be at least 5";
    if (!(o.ratio_threshold >= 1.0)) return "ratio_threshold must be at least 1";
    if (!(o.difference_threshold >= 0.0)) return "difference_threshold must not be negative";
    if (!(o.constraint_gate_sigma > 0.0)) return "constraint_gate_sigma must be positive";
    if (!(o.length_tolerance_m >= 0.0)) return "length_tolerance_m must not be negative";
    if (!(o.residual_test_pfa > 0.0 && o.residual_test_pfa < 1.0)) return "residual_test_pfa must be in (0, 1)";
    if (o.max_candidates_per_baseline < 2) return "max_candidates_per_baseline must be at least 2";
    if (!(o.multi_epoch_difference_threshold >= 0.0)) return "multi_epoch_difference_threshold must not be negative";
    if (o.multi_epoch_max_epochs < 2) return "multi_epoch_max_epochs must be at least 2";
    return "";
  }();
  if (why) *why = problem;
  return problem.empty();
}

AttitudeSolver::AttitudeSolver(AttitudeSolverOptions options) : options_(std::move(options)) {
  const std::string err = io::why_invalid(options_);
  if (!err.empty()) throw std::invalid_argument("AttitudeSolverOptions: " + err);
  reset();
}

void AttitudeSolver::reset() {
  const std::size_t n = options_.array.lever_arm_body_m.size();
  fixed_.clear();
  bias_mean_.assign(n, 0.0);
  bias_m2_.assign(n, 0.0);
  bias_count_.assign(n, 0);
  last_ratio_ = 0.0;
  pending_.clear();
  pending_rows_.clear();
  pending_epochs_ = pending_dof_ = 0;
  have_attitude_ = false;
  last_R_eb_.setIdentity();
}

namespace {

const SdAmbiguity* find_ambiguity(const std::vector<SdAmbiguity>& v, int antenna, int prn) {
  for (const SdAmbiguity& a : v) {
    if (a.antenna == antenna && a.prn == prn) return &a;
  }
  return nullptr;
}

double wrap_half(double x) { return x - std::floor(x + 0.5); }

// Whether the same integers also fit a clearly different attitude almost as well (within margin of chi-square).
// With few satellites a baseline's float can be weak along one direction; its mirror image across the plane normal
// to that direction has the same length, and the rigid fit started there can land in a second minimum. Both are
// tried for every baseline (all combinations but the fit's own): a second minimum means no unique attitude.
bool attitude_ambiguous(const ArrayFitter& fitter, const Eigen::VectorXd& z, const ArrayFit& fit,
                        const std::vector<Eigen::Vector3d>& body, double margin) {
  const DoubleDifferences& dd = fitter.dd();
  std::vector<Eigen::Vector3d> l, fitted, mirrored;
  for (int k = 1; k < dd.num_antennas; ++k) {
    const auto ku = static_cast<std::size_t>(k);
    if (dd.baseline_count[ku] == 0) continue;
    const BaselineFloat f = fitter.baseline_float(k, z);
    if (!f.ok) continue;
    const Eigen::Vector3d w = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(f.covariance).eigenvectors().col(2);
    const Eigen::Vector3d b = fit.R_eb * body[ku];
    l.push_back(body[ku]);
    fitted.push_back(b);
    mirrored.push_back(b - 2.0 * b.dot(w) * w);
  }
  const double sigma = std::sqrt(Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(fit.covariance_e).eigenvalues()(2));
  const std::size_t n = l.size();
  for (std::size_t mask = 1; mask < (std::size_t{1} << n); ++mask) {
    std::vector<Eigen::Vector3d> v(n);
    for (std::size_t i = 0; i < n; ++i) v[i] = (mask >> i) & 1 ? mirrored[i] : fitted[i];
    const Eigen::Matrix3d start = wahba_rotation(l, v, std::vector<double>(n, 1.0));
    const ArrayFit other = fitter.fit(z, &start);
    if (!other.ok || other.chi2 > fit.chi2 + margin) continue;
    const double angle = Eigen::AngleAxisd(other.R_eb * fit.R_eb.transpose()).angle();
    if (angle > std::max(6.0 * sigma, 1e-3)) return true;
  }
  return false;
}

}  // namespace

AttitudeSolution AttitudeSolver::update(const AntennaPhaseEpoch& epoch) {
  const auto& lever = options_.array.lever_arm_body_m;
  const int na = static_cast<int>(lever.size());
  std::vector<Eigen::Vector3d> body(lever.size());
  for (int k = 0; k < na; ++k) body[static_cast<std::size_t>(k)] = lever[static_cast<std::size_t>(k)] - lever[0];
  const double sigma_cycles = options_.phase_sigma_m / signals::kL1Wavelength_m;

  AttitudeSolution sol;
  sol.time = epoch.receive_time;
  sol.line_bias_cycles.assign(lever.size(), std::numeric_limits<double>::quiet_NaN());
  sol.line_bias_sigma_cycles.assign(lever.size(), std::numeric_limits<double>::quiet_NaN());
  sol.line_bias_cycles[0] = sol.line_bias_sigma_cycles[0] = 0.0;
  for (int k = 1; k < na; ++k) {
    const auto ku = static_cast<std::size_t>(k);
    if (bias_count_[ku] == 0) continue;
    sol.line_bias_cycles[ku] = wrap_half(bias_mean_[ku]);
    sol.line_bias_sigma_cycles[ku] = bias_count_[ku] >= 2
                                         ? std::sqrt(bias_m2_[ku] / (bias_count_[ku] - 1) / bias_count_[ku])
                                         : std::numeric_limits<double>::quiet_NaN();
  }

  if (!epoch.master_position_e.allFinite() || epoch.master_position_e.norm() < 1.0e6) return sol;

  std::vector<const AntennaPhaseObservation*> sats;
  for (const AntennaPhaseObservation& o : epoch.satellites) {
    if (o.elevation_rad >= options_.elevation_mask_rad && o.usable[0] && o.los_e.allFinite() &&
        std::abs(o.los_e.norm() - 1.0) < 1e-3) {
      sats.push_back(&o);
    }
  }
  auto usable = [&](std::size_t s, int k) {
    const AntennaPhaseObservation& o = *sats[s];
    return k < o.num_antennas && o.usable[static_cast<std::size_t>(k)] &&
           std::isfinite(o.carrier_phase_cycles[static_cast<std::size_t>(k)]) &&
           std::isfinite(o.carrier_phase_cycles[0]);
  };
  auto sat_index = [&](int prn) -> int {
    for (std::size_t s = 0; s < sats.size(); ++s) {
      if (sats[s]->prn == prn) return static_cast<int>(s);
    }
    return -1;
  };
  std::set<int> slipped;

  // 1. Ambiguities whose phase may have jumped (flags), or that are not seen now, restart.
  std::vector<SdAmbiguity> kept;
  for (const SdAmbiguity& a : fixed_) {
    const int s = sat_index(a.prn);
    if (s < 0 || !usable(static_cast<std::size_t>(s), a.antenna)) continue;
    const AntennaPhaseObservation& o = *sats[static_cast<std::size_t>(s)];
    if (o.slip[0] || o.slip[static_cast<std::size_t>(a.antenna)]) {
      slipped.insert(a.prn);
      continue;
    }
    kept.push_back(a);
  }
  fixed_ = std::move(kept);
  sol.slipped_prns.assign(slipped.begin(), slipped.end());

  const Eigen::Matrix3d C_en = ned_to_ecef_rotation(epoch.master_position_e);
  const double pfa = options_.residual_test_pfa;
  auto passes = [&](const ArrayFit& f) {
    return f.ok && f.dof >= 1 && f.chi2 <= chi_square_upper_quantile(f.dof, pfa);
  };
  // Carried DDs: the satellites with a kept ambiguity, on the baselines that keep at least 4 of them (3 DDs).
  auto carried_dd = [&]() {
    std::vector<int> kept_sats(lever.size(), 0);
    for (std::size_t s = 0; s < sats.size(); ++s) {
      for (int k = 1; k < na; ++k) {
        kept_sats[static_cast<std::size_t>(k)] +=
            usable(s, k) && find_ambiguity(fixed_, k, sats[s]->prn) != nullptr ? 1 : 0;
      }
    }
    return form_double_differences(sats, na, sigma_cycles, [&](std::size_t s, int k) {
      return kept_sats[static_cast<std::size_t>(k)] >= 4 && usable(s, k) &&
             find_ambiguity(fixed_, k, sats[s]->prn) != nullptr;
    });
  };
  auto carried_integers = [&](const DoubleDifferences& dd) {
    Eigen::VectorXd z(static_cast<Eigen::Index>(dd.rows.size()));
    for (std::size_t i = 0; i < dd.rows.size(); ++i) {
      const DdRow& r = dd.rows[i];
      z(static_cast<Eigen::Index>(i)) = static_cast<double>(find_ambiguity(fixed_, r.antenna, r.prn)->cycles -
                                                            find_ambiguity(fixed_, r.antenna, r.ref_prn)->cycles);
    }
    return z;
  };
  auto baselines_in = [&](const DoubleDifferences& dd) {
    int n = 0;
    for (int k = 1; k < na; ++k) n += dd.baseline_count[static_cast<std::size_t>(k)] > 0 ? 1 : 0;
    return n;
  };
  // The rigid fit from the previous attitude, and from Wahba's start when that fails (a long gap, a fast turn).
  auto carried_fit = [&](const ArrayFitter& fitter, const Eigen::VectorXd& z, const Eigen::Matrix3d* start) {
    ArrayFit f = fitter.fit(z, start);
    if (!passes(f) && start != nullptr) f = fitter.fit(z, nullptr);
    return f;
  };

  // Writes the solution from a validated fit and updates the line-bias calibration.
  auto emit = [&](const DoubleDifferences& dd, const ArrayFit& fit, bool new_fix) {
    sol.valid = sol.fixed = true;
    sol.new_fix = new_fix;
    sol.ratio = last_ratio_;
    sol.C_nb = C_en.transpose() * fit.R_eb;
    const EulerAngles e = euler_from_C_nb(sol.C_nb);
    sol.roll_rad = e.roll_rad;
    sol.pitch_rad = e.pitch_rad;
    sol.yaw_rad = e.yaw_rad;
    sol.covariance_rad2 = euler_covariance(sol.C_nb, C_en.transpose() * fit.covariance_e * C_en);
    for (int k = 1; k < na; ++k) sol.baseline_n_m.push_back(sol.C_nb * body[static_cast<std::size_t>(k)]);
    sol.residual_chi2 = fit.chi2;
    sol.residual_dof = fit.dof;
    std::set<std::size_t> used_sats;
    for (const DdRow& r : dd.rows) {
      used_sats.insert(r.sat);
      used_sats.insert(r.ref_sat);
    }
    sol.num_sats = static_cast<int>(used_sats.size());
    for (int k = 1; k < na; ++k) {
      const auto ku = static_cast<std::size_t>(k);
      if (dd.baseline_count[ku] == 0) continue;  // this antenna's ambiguities took no part in the fit
      const Eigen::Vector3d b_e = fit.R_eb * body[ku];
      double sum = 0.0;
      int n = 0;
      for (std::size_t s : used_sats) {
        const SdAmbiguity* a = find_ambiguity(fixed_, k, sats[s]->prn);
        if (a == nullptr || !usable(s, k)) continue;
        sum += single_difference_cycles(*sats[s], k) - single_difference_geometry(*sats[s]).dot(b_e) -
               static_cast<double>(a->cycles);
        ++n;
        sol.ambiguities.push_back(*a);
      }
      if (n == 0) continue;
      double d = sum / n;
      if (bias_count_[ku] > 0) d -= std::round(d - bias_mean_[ku]);
      ++bias_count_[ku];
      const double delta = d - bias_mean_[ku];
      bias_mean_[ku] += delta / bias_count_[ku];
      bias_m2_[ku] += delta * (d - bias_mean_[ku]);
      sol.line_bias_cycles[ku] = wrap_half(bias_mean_[ku]);
      // One epoch's mean of n SDs has the SD noise / sqrt(n); over epochs, the scatter of the epoch means.
      sol.line_bias_sigma_cycles[ku] = bias_count_[ku] >= 2
                                           ? std::sqrt(bias_m2_[ku] / (bias_count_[ku] - 1) / bias_count_[ku])
                                           : std::sqrt(2.0) * sigma_cycles / std::sqrt(static_cast<double>(n));
    }
    have_attitude_ = true;
    last_R_eb_ = fit.R_eb;
  };

  // 2. Carried ambiguities: rigid fit and residual check; then satellites without one join by rounding.
  if (!fixed_.empty()) {
    const DoubleDifferences dd = carried_dd();
    if (baselines_in(dd) >= 2) {
      const ArrayFitter fitter(dd, body);
      const ArrayFit fit = carried_fit(fitter, carried_integers(dd), have_attitude_ ? &last_R_eb_ : nullptr);
      if (!passes(fit)) {
        for (const SdAmbiguity& a : fixed_) slipped.insert(a.prn);
        fixed_.clear();
      } else {
        std::vector<SdAmbiguity> added;
        for (std::size_t s = 0; s < sats.size(); ++s) {
          for (int k = 1; k < na; ++k) {
            const auto ku = static_cast<std::size_t>(k);
            if (!usable(s, k) || find_ambiguity(fixed_, k, sats[s]->prn) != nullptr || bias_count_[ku] == 0) continue;
            const double v = single_difference_cycles(*sats[s], k) -
                             single_difference_geometry(*sats[s]).dot(fit.R_eb * body[ku]) - bias_mean_[ku];
            const double n = std::round(v);
            if (std::abs(v - n) < 0.2) added.push_back({k, sats[s]->prn, static_cast<long>(n)});
          }
        }
        if (!added.empty()) {
          const std::vector<SdAmbiguity> before = fixed_;
          fixed_.insert(fixed_.end(), added.begin(), added.end());
          const DoubleDifferences dd2 = carried_dd();
          const ArrayFitter fitter2(dd2, body);
          const ArrayFit fit2 = carried_fit(fitter2, carried_integers(dd2), &fit.R_eb);
          if (passes(fit2)) {
            emit(dd2, fit2, false);
            return sol;
          }
          fixed_ = before;
        }
        emit(dd, fit, false);
        return sol;
      }
    }
  }

  // 3. Resolution from scratch, this epoch alone.
  fixed_.clear();
  std::vector<int> count(lever.size(), 0);
  for (std::size_t s = 0; s < sats.size(); ++s) {
    for (int k = 1; k < na; ++k) count[static_cast<std::size_t>(k)] += usable(s, k) ? 1 : 0;
  }
  const DoubleDifferences dd = form_double_differences(sats, na, sigma_cycles, [&](std::size_t s, int k) {
    return usable(s, k) && count[static_cast<std::size_t>(k)] >= options_.min_satellites;
  });
  sol.slipped_prns.assign(slipped.begin(), slipped.end());
  if (dd.rows.empty()) return sol;
  const ArrayFitter fitter(dd, body);
  AmbiguityResolutionOptions ro;
  ro.use_constraints = options_.use_length_constraint;
  ro.gate_sigma = options_.constraint_gate_sigma;
  ro.length_tolerance_m = options_.length_tolerance_m;
  ro.ratio_threshold = options_.ratio_threshold;
  ro.difference_threshold = options_.difference_threshold;
  ro.residual_test_pfa = options_.residual_test_pfa;
  ro.max_candidates_per_baseline = options_.max_candidates_per_baseline;
  // The DD rows and whether any of their satellites carries a slip flag (for the multi-epoch candidates).
  std::vector<RowKey> rows;
  bool slip = false;
  for (const DdRow& r : dd.rows) {
    rows.push_back({r.antenna, r.prn, r.ref_prn});
    const auto k = static_cast<std::size_t>(r.antenna);
    slip = slip || sats[r.sat]->slip[0] || sats[r.sat]->slip[k] || sats[r.ref_sat]->slip[0] || sats[r.ref_sat]->slip[k];
  }
  const bool multi = options_.use_length_constraint && options_.multi_epoch;
  const bool continue_pending =
      multi && !pending_.empty() && rows == pending_rows_ && !slip && pending_epochs_ < options_.multi_epoch_max_epochs;
  Eigen::VectorXd integers;
  ArrayFit fit;
  double ratio = 0.0;
  if (continue_pending) {
    // 4. Multi-epoch: the candidates carried so far scored on this epoch (their integers stand while the phases
    // are continuous); the first epoch's search already holds every candidate worth a score.
    for (Hypothesis& h : pending_) {
      const ArrayFit f = fitter.fit(h.integers);
      h.chi2_sum += f.ok ? f.chi2 : std::numeric_limits<double>::infinity();
    }
    ++pending_epochs_;
    pending_dof_ += static_cast<int>(rows.size()) - 3;
    std::sort(pending_.begin(), pending_.end(), [](const auto& a, const auto& b) { return a.chi2_sum < b.chi2_sum; });
    const double j1 = pending_.front().chi2_sum;
    const double j2 = pending_.size() > 1 ? pending_[1].chi2_sum : std::numeric_limits<double>::infinity();
    sol.ratio = std::isfinite(j2) ? j2 / std::max(j1, 1e-12) : 1e9;
    if (j1 <= chi_square_upper_quantile(pending_dof_, pfa) && j2 - j1 >= options_.multi_epoch_difference_threshold) {
      const ArrayFit f = fitter.fit(pending_.front().integers);
      if (passes(f)) {
        integers = pending_.front().integers;
        fit = f;
        ratio = sol.ratio;
      }
    }
  } else {
    const AmbiguityResolution res = resolve_array_ambiguities(fitter, body, ro);
    sol.ratio = std::isfinite(res.ratio) ? res.ratio : 0.0;
    pending_.clear();
    pending_epochs_ = pending_dof_ = 0;
    if (res.fixed) {
      integers = res.integers;
      fit = res.fit;
      ratio = std::isfinite(res.ratio) ? res.ratio : 1e9;
    } else if (multi && !res.kept_truncated && !res.candidates.empty()) {
      // Not validated this epoch: its candidates start a multi-epoch test (a truncated list may have lost the
      // right candidate: wait for a better epoch to start from).
      for (const ArrayCandidate& c : res.candidates) pending_.push_back({c.integers, c.chi2});
      pending_rows_ = std::move(rows);
      pending_epochs_ = 1;
      pending_dof_ = static_cast<int>(pending_rows_.size()) - 3;
    }
  }
  if (integers.size() == 0) return sol;
  if (attitude_ambiguous(fitter, integers, fit, body, options_.difference_threshold)) return sol;
  pending_.clear();
  pending_epochs_ = pending_dof_ = 0;
  // The integers of one antenna get the datum that keeps its line bias where the calibration has it.
  for (int k = 1; k < na; ++k) {
    const auto ku = static_cast<std::size_t>(k);
    const int begin = dd.baseline_begin[ku];
    const int cnt = dd.baseline_count[ku];
    if (cnt == 0) continue;
    const Eigen::Vector3d b_e = fit.R_eb * body[ku];
    const std::size_t r = dd.rows[static_cast<std::size_t>(begin)].ref_sat;
    double sum = single_difference_cycles(*sats[r], k) - single_difference_geometry(*sats[r]).dot(b_e);
    for (int i = begin; i < begin + cnt; ++i) {
      const DdRow& row = dd.rows[static_cast<std::size_t>(i)];
      sum += single_difference_cycles(*sats[row.sat], k) - single_difference_geometry(*sats[row.sat]).dot(b_e) -
             integers(i);
    }
    const double mean = sum / (cnt + 1);
    const double c = bias_count_[ku] > 0 ? std::round(mean - bias_mean_[ku]) : std::round(mean);
    fixed_.push_back({k, sats[r]->prn, static_cast<long>(c)});
    for (int i = begin; i < begin + cnt; ++i) {
      fixed_.push_back({k, dd.rows[static_cast<std::size_t>(i)].prn, static_cast<long>(integers(i) + c)});
    }
  }
  last_ratio_ = ratio;
  emit(dd, fit, true);
  return sol;
}

}  // namespace ultratrack::receiver

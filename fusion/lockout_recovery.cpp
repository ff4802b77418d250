// SPDX-License-Identifier: GPL-3.0-or-later
#include "fusion/lockout_recovery.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>

#include "fusion/ins_error_state.hpp"

namespace ultratrack::fusion {

bool LockoutRecoveryOptions::IsValid(std::string* why) const {
  auto fail = [&](const char* w) {
    if (why) *why = w;
    return false;
  };
  if (consecutive_rejections < 1) return fail("lock-out recovery: consecutive_rejections must be at least 1");
  if (!(min_span_s >= 0.0) || !std::isfinite(min_span_s)) return fail("lock-out recovery: min_span_s must be >= 0");
  if (nis_window < 0) return fail("lock-out recovery: nis_window must be >= 0");
  if (!(nis_window_probability > 0.0 && nis_window_probability < 1.0))
    return fail("lock-out recovery: nis_window_probability must lie in (0, 1)");
  if (!(attitude_sigma_rad.array() > 0.0).all() || !attitude_sigma_rad.allFinite())
    return fail("lock-out recovery: attitude sigmas must be positive");
  return true;
}

namespace {

WindowedNisOptions window_options(const LockoutRecoveryOptions& o) {
  WindowedNisOptions w;
  w.window = std::max(o.nis_window, 1);  // (0: the test is off, observe never adds)
  w.probability = o.nis_window_probability;
  w.cap_per_dof = 100.0;  // one outlier alone cannot fill the window's budget
  return w;
}

}  // namespace

LockoutMonitor::LockoutMonitor(const LockoutRecoveryOptions& options)
    : opt_(options), window_(window_options(options)) {}

void LockoutMonitor::reset() {
  rejections_ = 0;
  window_.reset();
}

std::optional<RecoveryEvent> LockoutMonitor::observe(double t_s, bool accepted, double nis, int dof) {
  if (!opt_.enabled) return std::nullopt;
  if (accepted) {
    rejections_ = 0;
  } else if (rejections_++ == 0) {
    first_rejection_t_s_ = t_s;
  }
  if (rejections_ >= opt_.consecutive_rejections && t_s - first_rejection_t_s_ >= opt_.min_span_s) {
    RecoveryEvent e{t_s,
                    fmt::format("{} consecutive rejections over {:.1f} s", rejections_, t_s - first_rejection_t_s_)};
    reset();
    return e;
  }
  if (opt_.nis_window == 0 || dof <= 0) return std::nullopt;
  if (!window_.add(nis, dof)) return std::nullopt;
  RecoveryEvent e{t_s, fmt::format("windowed NIS {:.0f} over {} updates (limit {:.0f})", window_.sum(),
                                   window_.updates(), window_.limit())};
  reset();
  return e;
}

Eigen::MatrixXd inflate_for_recovery(const Eigen::MatrixXd& P_in, const Eigen::Vector3d& dp,
                                     const std::optional<Eigen::Vector3d>& dv, double span_s,
                                     const LockoutRecoveryOptions& o, std::optional<double> clock_innovation_m) {
  Eigen::MatrixXd P = P_in;
  const int n = static_cast<int>(P.rows());
  Eigen::VectorXd var = P.diagonal();
  const double v_from_p = 2.0 * dp.norm() / std::max(span_s, 1.0);
  for (int i = 0; i < 3; ++i) {
    var(ix::kPos + i) = std::max(var(ix::kPos + i), 4.0 * dp(i) * dp(i) + 1.0);
    const double dvi = dv ? (*dv)(i) : v_from_p;
    var(ix::kVel + i) = std::max(var(ix::kVel + i), 4.0 * dvi * dvi + 1.0);
    var(ix::kAtt + i) = std::max(var(ix::kAtt + i), o.attitude_sigma_rad(i) * o.attitude_sigma_rad(i));
  }
  std::vector<int> opened{ix::kPos,     ix::kPos + 1, ix::kPos + 2, ix::kVel,    ix::kVel + 1,
                          ix::kVel + 2, ix::kAtt,     ix::kAtt + 1, ix::kAtt + 2};
  if (clock_innovation_m && n >= 17) {
    const double dc = *clock_innovation_m;
    var(ix::kClockBias) = std::max(var(ix::kClockBias), 4.0 * dc * dc + 1.0);
    var(ix::kClockDrift) = std::max(var(ix::kClockDrift), 4.0 * v_from_p * v_from_p + 1.0);
    opened.push_back(ix::kClockBias);
    opened.push_back(ix::kClockDrift);
  }
  for (int i : opened) {
    P.row(i).setZero();
    P.col(i).setZero();
  }
  for (int i : opened) P(i, i) = var(i);
  return P;
}

}  // namespace ultratrack::fusion

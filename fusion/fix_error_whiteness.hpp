// SPDX-License-Identifier: GPL-3.0-or-later
// Whether a file of GNSS fixes has white errors at its own rate, measured from the fixes alone (no INS, no truth),
// and the first-order Gauss-Markov model the loose filter carries when it has not (fusion/fix_error_model.hpp).
// A receiver's smoothing, multipath and the atmosphere keep a fix's error for tens of seconds: a 20 Hz file may hold a
// few independent errors a minute, and a filter that takes them as white averages them down as if they were
// thousands, claims a sigma it does not have and lets the wandering errors steer its attitude.
//
// Method: third differences of the positions at a lag of m fixes (interval T),
//   d(m) = p(t + 3mT) - 3 p(t + 2mT) + 3 p(t + mT) - p(t),
// cancel the vehicle's motion up to a constant acceleration (a jerk j leaves j (mT)^3: 5 cm at 1 s for 0.05 m/s^3;
// it adds to the slope below, so a tau comes out short). Runs need each interval within 50 % of the median T;
// uneven times (time-stamp jitter) take the divided difference's weights, which cancel a constant acceleration at any
// spacing and are (-1, 3, -3, 1) when even.
// For a fix error e = w + c, w white (variance s_w^2), c Gauss-Markov (s_c^2, tau), q = exp(-mT / tau):
//   Var d(m) = 20 s_w^2 + s_c^2 (20 - 30 q + 12 q^2 - 2 q^3) = 20 s_w^2 + 12 s_c^2 mT / tau + O((mT / tau)^3).
// Two lags, 1 and M (MT about 1 s), give the white part (the intercept; the slope is taken off only when above twice
// its 1-sigma) and s_c^2 / tau (the slope), each as a share of the fixes' stated variance s^2 = s_w^2 + s_c^2, per
// axis. Each variance is robust (the median of d^2 / s^2 over
// 0.4549, the median of chi-square with one degree of freedom): a jump or an outlier does not move it. The slope's
// 1-sigma comes from eight contiguous blocks of the file.
// Verdict (horizontal axes): white when the white part explains at least half the stated variance (a simulator's
// white noise; errors that decorrelate within the fix interval). Else Gauss-Markov with
// s_c^2 = (1 - white share) s^2 per axis and tau = 12 (s_c^2 / s^2) T / slope; when the slope is below twice its
// 1-sigma the correlation is slower than the lags can see and tau is that bound, 12 (s_c^2 / s^2) T / (2 sigma).
// tau is kept within [MT, max_correlation_time_s].
// What it cannot see: a stated sigma that understates a correlated error (the stated variance is taken as the total,
// so tau comes out short by the square of the understatement: still far better than white), and a stated sigma that
// overstates white noise reads as correlated (a cautious filter). The configuration's [gnss]
// error_correlation_time_s overrides the verdict.
#pragma once

#include <Eigen/Core>
#include <span>
#include <string>

#include "fusion/loose_measurements.hpp"

namespace ultratrack::fusion {

struct FixWhitenessOptions {
  double long_lag_s = 1.0;                // M = round(long_lag_s / T), within [2, 20]
  int min_differences = 200;              // third differences needed at each lag for a verdict
  double white_share_threshold = 0.5;     // white below this share of the stated variance: correlated
  double understated_share = 1.5;         // white above this share: the stated sigma understates the noise
  double max_correlation_time_s = 300.0;  // tau at most this
};

struct FixErrorWhiteness {
  bool measured = false;      // enough regularly spaced position fixes for a verdict
  bool correlated = false;    // the fixes' errors are not white at their rate
  double interval_s = 0.0;    // the fixes' median interval T
  int long_lag = 0;           // M, in fixes
  long long differences = 0;  // third differences at lag 1 (regularly spaced runs of four fixes)
  // Per axis N, E, D: the white part's share of the stated variance (1: white at the fix rate; well above 1: the
  // stated sigma understates the noise), and Var d(M) / Var d(1) (1 for white errors, M for tau >> MT).
  Eigen::Vector3d white_share = Eigen::Vector3d::Ones();
  Eigen::Vector3d growth = Eigen::Vector3d::Ones();
  // When correlated: the model for fusion/fix_error_model.hpp.
  double correlation_time_s = 0.0;
  bool correlation_time_is_bound = false;                 // the slope was not significant: tau is its lower bound
  Eigen::Vector3d sigma_ned_m = Eigen::Vector3d::Zero();  // the correlated part's 1-sigma (median stated sigma)
  // White, per axis: the stated sigmas times this (the root of a white share above understated_share, else 1): the
  // data show more white noise than the file states.
  Eigen::Vector3d sigma_scale = Eigen::Vector3d::Ones();
  std::string note;  // one line for the user
};

// fixes: in time order; those without a position are skipped.
FixErrorWhiteness measure_fix_error_whiteness(std::span<const GnssFix> fixes, const FixWhitenessOptions& options = {});

// The velocities of the same fixes against the sigma the configuration tells (the fix file has none): third
// differences at lags of 1 and 2 fixes (a snap s of the vehicle leaves s (2T)^3: for 1 m/s^4, 1 mm/s at 20 Hz and 6
// cm/s at 5 Hz, against 0.22 m/s of 0.05 m/s white noise). A receiver that smooths its velocities shows a slope above
// twice its 1-sigma; then tau = 12 (1 - white share) T / slope, and each velocity's variance is widened by 1 + 2 tau /
// T, the information of the 2 tau / T + 1 fixes that share an error. Without a significant slope the velocities are
// used as told (a told sigma above the white noise is cautious, not wrong), unless their white noise is above it
// (a white share above understated_share): the variance is then widened by that share. Horizontal axes decide.
struct VelocityWhiteness {
  bool measured = false, correlated = false;
  double interval_s = 0.0;
  long long differences = 0;
  Eigen::Vector3d white_share = Eigen::Vector3d::Ones();  // Var d(1) / (20 sigma^2), N E (D not measured)
  double correlation_time_s = 0.0;
  double variance_factor = 1.0;  // each velocity fix's variance times this
  std::string note;
};

VelocityWhiteness measure_velocity_whiteness(std::span<const GnssFix> fixes, double sigma_mps,
                                             const FixWhitenessOptions& options = {});

}  // namespace ultratrack::fusion

// SPDX-License-Identifier: GPL-3.0-or-later
#include "fusion/ultratight_measurement_models.hpp"

#include <algorithm>
#include <cmath>

#include "signals/gps_constants.hpp"

namespace ultratrack::fusion {
namespace {

constexpr double kLambda_m = signals::kL1Wavelength_m;
constexpr double kChip_m = signals::kSpeedOfLight_mps / signals::kCaChipRate_hz;

}  // namespace

Eigen::Matrix2d period_mixing(double span_s) {
  Eigen::Matrix2d M = Eigen::Matrix2d::Identity();
  M(0, 1) = -0.5 * span_s;
  return M;
}

double period_span_s(double t_update_s, double replica_t_start_s, double period_s) {
  return 2.0 * (t_update_s - replica_t_start_s) - period_s;
}

Eigen::Vector2d period_signal_offset(double replica_range_start_m, double replica_rate_mps, double replica_t_start_s,
                                     double period_s, double t_update_s, double signal_range_m, double signal_rate_mps,
                                     double signal_rate_slope_mps2) {
  const double back_end = t_update_s - (replica_t_start_s + period_s);
  const double rate_end = signal_rate_mps - signal_rate_slope_mps2 * back_end;
  const double range_end = signal_range_m - 0.5 * (rate_end + signal_rate_mps) * back_end;
  return period_replica_errors(replica_range_start_m, replica_rate_mps, range_end,
                               rate_end - signal_rate_slope_mps2 * period_s, rate_end, period_s);
}

double prior_code_sigma_chips(const ReplicaErrors17& replica, const StateMatrix<17>& P, double span_s) {
  const MeasurementJacobian<17> J = replica.jacobian();
  const Eigen::Matrix<double, 1, 17> h_range = J.row(0) - 0.5 * span_s * J.row(1);
  return std::sqrt(std::max(0.0, (h_range * P * h_range.transpose())(0, 0))) / kChip_m;
}

double prompt_code_slope_weight(double code_error_chips, double prior_code_sigma_chips) {
  if (!(prior_code_sigma_chips > 0.0)) return 1.0;
  return std::erf(std::abs(code_error_chips) / (std::sqrt(2.0) * prior_code_sigma_chips));
}

PeriodIqMeasurement::PeriodIqMeasurement(const NominalState& nominal, const SatelliteObservable& sat,
                                         const Eigen::Vector3d& lever_arm_b, const Eigen::Vector3d& w_ib_b,
                                         const IqSettings& settings, const IqTaps& measured,
                                         const IqPeriodOptions& period)
    : replica_(nominal, {sat}, lever_arm_b, w_ib_b),
      s_(settings),
      offset_(period.offset),
      M_(period_mixing(period.span_s)),
      R_(iq_noise_covariance(settings)),
      code_sigma_(period.prior_code_sigma_chips),
      start_phase_(period.start_phase_rad) {
  const TrackingErrors at_nominal = errors(StateVector<17>::Zero());
  if (period.clock_rate_var_m2ps2 > 0.0) {
    const Vector6 g = iq_jacobian(at_nominal, s_).col(1) / kLambda_m;
    R_ += period.clock_rate_var_m2ps2 * g * g.transpose();
  }
  if (period.start_phase_var_rad2 > 0.0) {
    const Vector6 g = iq_phase_derivative(at_nominal, s_);
    R_ += period.start_phase_var_rad2 * g * g.transpose();
  }
  for (int k = 0; k < 3; ++k) {
    z_(k) = measured.i[k];
    z_(3 + k) = measured.q[k];
  }
}

TrackingErrors PeriodIqMeasurement::errors(const StateVector<17>& dx) const {
  const Eigen::Vector2d e = M_ * replica_.errors(0, dx) + offset_;
  TrackingErrors te = tracking_errors(e(0), e(1));
  te.phase_rad = start_phase_;
  return te;
}

PeriodIqMeasurement::Vector6 PeriodIqMeasurement::h(const StateVector<17>& dx) const {
  const IqTaps t = expected_iq(errors(dx), s_);
  Vector6 out;
  for (int k = 0; k < 3; ++k) {
    out(k) = t.i[k];
    out(3 + k) = t.q[k];
  }
  return out;
}

MeasurementJacobian<17> PeriodIqMeasurement::H(const StateVector<17>& dx) const {
  const TrackingErrors te = errors(dx);
  Eigen::Matrix<double, 6, 2> J = iq_jacobian(te, s_);
  if (code_sigma_ > 0.0) {
    const double w = prompt_code_slope_weight(te.code_chips, code_sigma_);
    J(1, 0) *= w;
    J(4, 0) *= w;
  }
  const Eigen::Matrix<double, 2, 2> D = Eigen::Vector2d(1.0 / kChip_m, 1.0 / kLambda_m).asDiagonal();
  return J * D * M_ * replica_.jacobian();
}

Eigen::Vector2d period_discriminator_errors(const IqTaps& taps, const IqSettings& settings, double start_phase_rad) {
  const double f_hz =
      frequency_discriminator_hz(taps, settings) - start_phase_rad / (M_PI * settings.integration_time_s);
  return {code_discriminator_chips(taps, settings) * kChip_m, f_hz * kLambda_m};
}

double start_phase_rate_variance(double start_phase_var_rad2, double period_s) {
  return start_phase_var_rad2 * std::pow(kLambda_m / (M_PI * period_s), 2);
}

PeriodDiscriminatorMeasurement::PeriodDiscriminatorMeasurement(
    const NominalState& nominal, const SatelliteObservable& sat, const Eigen::Vector3d& lever_arm_b,
    const Eigen::Vector3d& w_ib_b, const Eigen::Vector2d& offset, double span_s, const Eigen::Vector2d& measured,
    const DiscriminatorNoise& noise, double clock_rate_var_m2ps2, double start_phase_rate_var_m2ps2)
    : replica_(nominal, {sat}, lever_arm_b, w_ib_b),
      offset_(offset),
      M_(period_mixing(span_s)),
      z_(measured),
      R_(Eigen::MatrixXd::Zero(2, 2)) {
  R_(0, 0) = noise.range_sigma_m * noise.range_sigma_m;
  R_(1, 1) = noise.rate_sigma_mps * noise.rate_sigma_mps + clock_rate_var_m2ps2 + start_phase_rate_var_m2ps2;
}

}  // namespace ultratrack::fusion

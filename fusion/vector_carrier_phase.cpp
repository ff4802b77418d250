// SPDX-License-Identifier: GPL-3.0-or-later
#include "fusion/vector_carrier_phase.hpp"

#include <algorithm>

namespace ultratrack::fusion {

double costas_discriminator_cycles(double i, double q) {
  if (i == 0.0) return q == 0.0 ? 0.0 : (q > 0.0 ? 0.25 : -0.25);
  return std::atan(q / i) / (2.0 * M_PI);
}

double loop_noise_bandwidth_hz(double k_phase, double k_freq, double t_s) {
  if (!(k_phase > 0.0) || !(t_s > 0.0)) return NAN;
  return (k_phase / t_s + k_freq / k_phase) / 4.0;
}

void VectorCarrierPhase::start(std::int64_t at, double replica_phase_cycles, double discriminator_cycles, double nu0_hz,
                               double disc_variance_cycles2) {
  active_ = true;
  fell_back_ = false;
  sample_ = at;
  x_ << replica_phase_cycles + discriminator_cycles, nu0_hz;
  P_.setZero();
  P_(0, 0) = disc_variance_cycles2;
  P_(1, 1) = opt_.initial_sigma_frequency_hz * opt_.initial_sigma_frequency_hz;
  dot_ = power_ = averaged_s_ = below_s_ = 0.0;
  disc_ = discriminator_cycles;
  innovation_ = bn_hz_ = NAN;
  fallback_s = 0.0;
  command_base_hz_.fill(NAN);
}

void VectorCarrierPhase::record_command(std::int64_t from, double base_hz) {
  // Newest first; a command for the same start replaces the previous one (the channel takes the latest).
  if (std::isfinite(command_base_hz_[0]) && command_from_[0] == from) {
    command_base_hz_[0] = base_hz;
    return;
  }
  for (std::size_t i = command_from_.size() - 1; i > 0; --i) {
    command_from_[i] = command_from_[i - 1];
    command_base_hz_[i] = command_base_hz_[i - 1];
  }
  command_from_[0] = from;
  command_base_hz_[0] = base_hz;
}

double VectorCarrierPhase::commanded_base_hz(std::int64_t at) const {
  for (std::size_t i = 0; i < command_from_.size(); ++i)
    if (std::isfinite(command_base_hz_[i]) && command_from_[i] <= at) return command_base_hz_[i];
  return NAN;
}

void VectorCarrierPhase::propagate(std::int64_t to, double fs_hz, double mean_predicted_doppler_hz,
                                   double prediction_variance_hz2) {
  const double dt = static_cast<double>(to - sample_) / fs_hz;
  if (!(dt > 0.0)) return;  // the state only moves forward (epochs arrive in order)
  sample_ = to;
  // nu: Gauss-Markov, a = exp(-dt / tau); psi integrates it exactly (tau (1 - a) nu).
  const double tau = opt_.frequency_correlation_s;
  const double a = std::exp(-dt / tau);
  Eigen::Matrix2d F;
  F << 1.0, tau * (1.0 - a), 0.0, a;
  x_(0) += mean_predicted_doppler_hz * dt;
  x_ = F * x_;
  // Driving noise of nu over dt (random-walk form: tau >> dt), integrated into psi.
  const double q = opt_.frequency_psd_hz2ps, h = dt;
  Eigen::Matrix2d Q;
  Q << q * h * h * h / 3.0, q * h * h / 2.0, q * h * h / 2.0, q * h;
  Q(0, 0) += prediction_variance_hz2 * h * h;
  P_ = F * P_ * F.transpose() + Q;
}

double VectorCarrierPhase::phase_at(std::int64_t to, double fs_hz, double mean_predicted_doppler_hz) const {
  const double dt = static_cast<double>(to - sample_) / fs_hz;
  const double tau = opt_.frequency_correlation_s;
  return x_(0) + mean_predicted_doppler_hz * dt + tau * (1.0 - std::exp(-dt / tau)) * x_(1);
}

bool VectorCarrierPhase::update(double prompt_i, double prompt_q, double replica_phase_cycles, double variance_cycles2,
                                double epoch_s) {
  // Lock indicator (Costas): cos 2 phi from the running means of I^2 - Q^2 and I^2 + Q^2.
  const double w = std::min(1.0, epoch_s / opt_.lock_average_s);
  dot_ += w * (prompt_i * prompt_i - prompt_q * prompt_q - dot_);
  power_ += w * (prompt_i * prompt_i + prompt_q * prompt_q - power_);
  averaged_s_ += epoch_s;
  if (averaged_s_ >= opt_.lock_average_s) below_s_ = lock_indicator() < opt_.lock_threshold ? below_s_ + epoch_s : 0.0;

  disc_ = costas_discriminator_cycles(prompt_i, prompt_q);
  // The predicted discriminator and the innovation modulo half a cycle (a Costas discriminator cannot tell).
  const double predicted = x_(0) - replica_phase_cycles;
  innovation_ = disc_ - predicted;
  innovation_ -= 0.5 * std::round(innovation_ / 0.5);
  prior_sigma_ = std::sqrt(P_(0, 0));
  const double s = P_(0, 0) + variance_cycles2;
  if (innovation_ * innovation_ > opt_.gate_sigma * opt_.gate_sigma * s) return false;
  const Eigen::Vector2d k = P_.col(0) / s;
  x_ += k * innovation_;
  P_ -= k * P_.row(0);
  P_ = 0.5 * (P_ + P_.transpose());
  bn_hz_ = loop_noise_bandwidth_hz(k(0), k(1), epoch_s);
  return true;
}

}  // namespace ultratrack::fusion

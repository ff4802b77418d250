// SPDX-License-Identifier: GPL-3.0-or-later
#include "receiver/lock_detectors.hpp"

#include <algorithm>
#include <cmath>

namespace ultratrack::receiver {

double PhaseLockIndicator::update(std::complex<float> prompt, double noise_power, double t_s) {
  const double i = prompt.real(), q = prompt.imag();
  const double narrow = i * i - q * q;
  const double wide = i * i + q * q - noise_power;
  if (!started_) {
    narrow_ = narrow;
    wide_ = wide;
    started_ = true;
  } else {
    const double alpha = std::min(1.0, t_s / tau_s_);
    narrow_ += alpha * (narrow - narrow_);
    wide_ += alpha * (wide - wide_);
  }
  // With no signal the denominator hovers around 0: bound the indicator to its physical range.
  value_ = wide_ > 0.0 ? std::clamp(narrow_ / wide_, -1.0, 1.0) : 0.0;
  return value_;
}

std::optional<double> Cn0Estimator::add(std::complex<float> prompt, std::complex<float> noise, double t_s) {
  const double p2 = std::norm(std::complex<double>(prompt));
  m2_ += p2;
  m4_ += p2 * p2;
  noise_ += std::norm(std::complex<double>(noise));
  if (++n_ < window_) return std::nullopt;
  const double m2 = m2_ / n_, m4 = m4_ / n_, pn_tap = noise_ / n_;
  reset();
  double signal = 0.0, noise_power = 0.0;
  if (method_ == Cn0Method::kMoments) {
    // |P|^2 = S + noise: E|P|^2 = S + N, E|P|^4 = S^2 + 4 S N + 2 N^2  =>  S = sqrt(2 M2^2 - M4).
    signal = std::sqrt(std::max(0.0, 2.0 * m2 * m2 - m4));
    noise_power = m2 - signal;
  } else {
    noise_power = pn_tap;
    signal = m2 - pn_tap;
  }
  if (signal <= 0.0 || noise_power <= 0.0 || t_s <= 0.0)
    return signal > 0.0 && noise_power <= 0.0 ? 99.0 : kNoSignalDbHz;
  return std::max(kNoSignalDbHz, 10.0 * std::log10(signal / (noise_power * t_s)));
}

}  // namespace ultratrack::receiver

// SPDX-License-Identifier: GPL-3.0-or-later
#include "receiver/vector_frequency_discriminator.hpp"

#include <cmath>

#include "receiver/discriminators.hpp"

namespace ultratrack::receiver {
namespace {

double costas_phase_variance_cycles2(double cn0_hz, double t_s) {
  const double snr = t_s * cn0_hz;  // pre-detection SNR of one epoch
  const double rad2 = 1.0 / (2.0 * snr) * (1.0 + 1.0 / (2.0 * snr));
  return rad2 / (kTwoPi * kTwoPi);
}
}  // namespace

double costas_phase_change_cycles(std::complex<float> first, std::complex<float> second) {
  double d = costas_atan_cycles(second) - costas_atan_cycles(first);
  if (d > 0.25) d -= 0.5;
  if (d <= -0.25) d += 0.5;
  return d;
}

double wiped_phase_change_cycles(std::complex<float> first, std::complex<float> second, int sign_product) {
  const std::complex<double> z = std::conj(std::complex<double>(first)) * std::complex<double>(second) *
                                 static_cast<double>(sign_product < 0 ? -1 : 1);
  return std::arg(z) / kTwoPi;
}

double phase_change_frequency_variance_hz2(double cn0_hz, double t_s, double dt_s) {
  return 2.0 * costas_phase_variance_cycles2(cn0_hz, t_s) / (dt_s * dt_s);
}

}  // namespace ultratrack::receiver

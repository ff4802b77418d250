// SPDX-License-Identifier: GPL-3.0-or-later
#include "receiver/loop_filters.hpp"

namespace ultratrack::receiver {

CarrierLoopFilter::CarrierLoopFilter(int order, double pll_bw_hz, double fll_bw_hz, double initial_frequency_hz)
    : order_(checked_order(order)), frequency_hz_(initial_frequency_hz) {
  set_bandwidths(pll_bw_hz, fll_bw_hz);
}

void CarrierLoopFilter::set_bandwidths(double pll_bw_hz, double fll_bw_hz) {
  pll_bw_hz_ = pll_bw_hz;
  fll_bw_hz_ = fll_bw_hz;
}

double CarrierLoopFilter::update(double phase_error_cycles, double frequency_error_hz, double t_s) {
  const double e = phase_error_cycles;
  const double ef = fll_bw_hz_ > 0.0 ? frequency_error_hz : 0.0;
  if (order_ == 2) {
    // PLL: F(s) = a2 w0 + w0^2 / s; FLL (1st order): w0f / s on the frequency error.
    const double w0 = pll_bw_hz_ / kSecondOrderBnPerW0;
    const double w0f = fll_bw_hz_ / kFirstOrderBnPerW0;
    const double previous = frequency_hz_;
    frequency_hz_ += t_s * (w0 * w0 * e + w0f * ef);
    return 0.5 * (frequency_hz_ + previous) + 1.4142135623730951 * w0 * e;
  }
  // PLL: F(s) = b3 w0 + a3 w0^2 / s + w0^3 / s^2; FLL (2nd order): a2 w0f / s + w0f^2 / s^2.
  const double w0 = pll_bw_hz_ / kThirdOrderBnPerW0;
  const double w0f = fll_bw_hz_ / kSecondOrderBnPerW0;
  const double previous_rate = rate_hzps_;
  rate_hzps_ += t_s * (w0 * w0 * w0 * e + w0f * w0f * ef);
  const double previous = frequency_hz_;
  frequency_hz_ += t_s * (0.5 * (rate_hzps_ + previous_rate) + 1.1 * w0 * w0 * e + 1.4142135623730951 * w0f * ef);
  return 0.5 * (frequency_hz_ + previous) + 2.4 * w0 * e;
}

}  // namespace ultratrack::receiver

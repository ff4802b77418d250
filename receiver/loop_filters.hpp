// SPDX-License-Identifier: GPL-3.0-or-later
// Digital loop filters for carrier and code tracking in Kaplan's standard form (Understanding GPS, 2nd ed.,
// Table 5.6 and Fig. 5.16: analogue prototypes with natural frequency w0 from the one-sided noise bandwidth Bn,
// integrators discretised by the bilinear (trapezoidal) rule). Inputs are discriminator outputs in cycles (PLL),
// Hz (FLL) or chips (DLL); outputs are the NCO frequency in Hz or the code-rate correction in chips/s.
// Bandwidths are the analogue design values: the digital loop (with the NCO's one-epoch delay) matches them
// within ~5 % for Bn*T <= 0.02 and widens as Bn*T grows (about +20 % at 0.1, +55 % at 0.2; tested).
#pragma once

#include <cmath>
#include <stdexcept>

namespace ultratrack::receiver {

// Kaplan Table 5.6 coefficients: w0 = Bn / k, a2 = sqrt(2), (a3, b3) = (1.1, 2.4).
inline constexpr double kSecondOrderBnPerW0 = 0.53;
inline constexpr double kThirdOrderBnPerW0 = 0.7845;
inline constexpr double kFirstOrderBnPerW0 = 0.25;

// Carrier loop: PLL of order 2 or 3, optionally assisted by an FLL (order one less than the PLL: Kaplan's
// FLL-assisted PLL). State: frequency (Hz) and, for order 3, frequency rate (Hz/s).
class CarrierLoopFilter final {
 public:
  // pll_bw_hz > 0; fll_bw_hz >= 0 (0 = no FLL assist); order 2 or 3 (std::invalid_argument otherwise: the tracking
  // options have checked it, so another value here is a programming error, not something to round).
  CarrierLoopFilter(int order, double pll_bw_hz, double fll_bw_hz, double initial_frequency_hz);

  void set_bandwidths(double pll_bw_hz, double fll_bw_hz);
  // Switches between 2nd and 3rd order keeping the frequency; the frequency-rate state restarts at 0.
  void set_order(int order) {
    order_ = checked_order(order);
    rate_hzps_ = 0.0;
  }
  // Restarts the integrators (e.g. when the integration time changes and the old state is too noisy).
  void reset(double frequency_hz, double frequency_rate_hzps) {
    frequency_hz_ = frequency_hz;
    rate_hzps_ = frequency_rate_hzps;
  }
  // One update with the phase error (cycles) and frequency error (Hz, ignored when the FLL is off) measured over
  // an integration of t_s seconds. Returns the NCO carrier frequency for the next integration, Hz.
  double update(double phase_error_cycles, double frequency_error_hz, double t_s);

  // A first-order FLL alone (w0 = Bn / 0.25), used for pull-in before any phase is tracked; the frequency-rate
  // state is cleared (it would otherwise random-walk on the FLL's noise). Returns the NCO frequency, Hz.
  double update_fll_only(double frequency_error_hz, double fll_bw_hz, double t_s) {
    rate_hzps_ = 0.0;
    frequency_hz_ += t_s * fll_bw_hz / kFirstOrderBnPerW0 * frequency_error_hz;
    return frequency_hz_;
  }

  double frequency_hz() const { return frequency_hz_; }
  double frequency_rate_hzps() const { return rate_hzps_; }
  int order() const { return order_; }
  double pll_bw_hz() const { return pll_bw_hz_; }
  double fll_bw_hz() const { return fll_bw_hz_; }

 private:
  static int checked_order(int order) {
    if (order != 2 && order != 3) throw std::invalid_argument("carrier loop: order must be 2 or 3");
    return order;
  }

  int order_;
  double pll_bw_hz_ = 0.0, fll_bw_hz_ = 0.0;
  double frequency_hz_;     // velocity integrator
  double rate_hzps_ = 0.0;  // acceleration integrator (order 3)
};

// Code loop: first-order DLL (carrier aided, so the aiding removes the code Doppler and the loop only tracks
// the residual): correction = 4 Bn * tau chips/s (w0 = Bn / 0.25).
inline double dll_rate_correction_chips_per_s(double code_error_chips, double dll_bw_hz) {
  return code_error_chips * dll_bw_hz / kFirstOrderBnPerW0;
}

// Thermal code jitter of a noncoherent early-minus-late DLL, chips (Kaplan, Understanding GPS 2nd ed., eq. 5.72):
// sqrt(Bn D / (2 c) (1 + 2 / (T c (2 - D)))), c = 10^(cn0_dbhz / 10), D = early-late spacing in chips (<= 1),
// T the predetection time. 1 Hz, D = 1, 20 ms: 0.0235 chip (6.9 m) at 30 dB-Hz, 0.030 (8.9 m) at 28.
inline double dll_thermal_jitter_chips(double bn_hz, double spacing_chips, double t_s, double cn0_dbhz) {
  const double c = std::pow(10.0, cn0_dbhz / 10.0);
  return std::sqrt(bn_hz * spacing_chips / (2.0 * c) * (1.0 + 2.0 / (t_s * c * (2.0 - spacing_chips))));
}

// The code error of the first-order DLL above is not white: each update t_s keeps 1 - 4 Bn t_s of it, so readings
// interval_s apart correlate by rho = (1 - 4 Bn t_s)^(interval_s / t_s) (0.66 for 1 Hz, 20 ms updates, 0.1 s
// epochs). A filter that takes such readings as independent gains N readings' information where the mean of N
// AR(1) samples has variance (sigma^2 / N) (1 + rho) / (1 - rho) (large N). This returns the factor on the
// 1-sigma of a white sequence of the same information, sqrt((1 + rho) / (1 - rho)) (2.21 for the numbers above;
// 1 when interval_s is long against the loop's time constant). Requires 0 < 4 Bn t_s < 1.
inline double dll_white_equivalent_sigma_factor(double bn_hz, double t_s, double interval_s) {
  const double keep = 1.0 - 4.0 * bn_hz * t_s;
  const double rho = std::pow(keep, interval_s / t_s);
  return std::sqrt((1.0 + rho) / (1.0 - rho));
}

}  // namespace ultratrack::receiver

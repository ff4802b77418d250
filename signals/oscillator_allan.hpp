// SPDX-License-Identifier: GPL-3.0-or-later
// A receiver oscillator described by its power-law (Allan variance) coefficients, and the typical values of
// Brown & Hwang's table ("Introduction to Random Signals and Applied Kalman Filtering", the two-state clock
// model): the fractional-frequency PSD S_y(f) = h0 + h-2 / f^2 (h0 in s, h-2 in 1/s); the flicker term h-1 is
// left out, as in their approximation. The synthesiser's clock (receiver_clock.hpp) and the filters' clock
// process noise (fusion/clock_model.hpp) are both derived from it, so a scenario and a filter configured with
// the same oscillator agree.
//
// Allan variance of such a clock (closed form): sigma_y^2(tau) = h0 / (2 tau) + (2 pi^2 / 3) h-2 tau.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "signals/receiver_clock.hpp"

namespace ultratrack::signals {

struct OscillatorAllan {
  double h0 = 2e-19;        // white frequency, s
  double h_minus2 = 2e-20;  // random-walk frequency, 1/s
};

// Brown & Hwang's "tcxo" (temperature-compensated crystal: h0 2e-19, h-2 2e-20) and "ocxo" (oven-controlled:
// h0 8e-20, h-2 4e-23), the filters' clock process noise; nothing for another name. Their h0 summarises the
// stability at a second and more, where flicker frequency noise (which the two-state model leaves out) rules.
std::optional<OscillatorAllan> oscillator_preset(const std::string& name);
std::vector<std::string> oscillator_preset_names();

// The same oscillators as a signal sees them over a tracking loop's milliseconds (the simulator's presets):
// white frequency noise from a class datasheet's phase noise at 1 kHz offset, h0 = 2 f^2 L(f) / nu^2 (TCXO at
// 26 MHz, -135 dBc/Hz: 9.4e-23; OCXO at 10 MHz, -150 dBc/Hz: 2.0e-23), random-walk frequency as above.
// Extrapolated to milliseconds, Brown & Hwang's h0 would be a phase random walk of 9.8 rad^2/s at L1: ~20 deg of
// jitter in a 15 Hz PLL (linear theory, q / (4 zeta omega_n)), which no GNSS receiver on a TCXO shows.
std::optional<OscillatorAllan> oscillator_signal_preset(const std::string& name);

// The synthesiser's random walks for these coefficients: the clock error b (s) diffuses with PSD h0 / 2
// (white frequency), its rate with PSD 2 pi^2 h-2 (random-walk frequency). Bias and drift at t = 0 are 0.
ReceiverClockModel receiver_clock_from_allan(const OscillatorAllan& allan);

// sigma_y(tau), the Allan deviation the coefficients imply (dimensionless).
double allan_deviation(const OscillatorAllan& allan, double tau_s);

}  // namespace ultratrack::signals

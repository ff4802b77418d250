// SPDX-License-Identifier: GPL-3.0-or-later
// Receiver clock process noise from the oscillator's power-law (Allan variance) coefficients, two-state model
// bias' = drift + w_b, drift' = w_d (Brown & Hwang, Introduction to Random Signals and Applied Kalman
// Filtering, the "two-state clock model"): S_b = c^2 h0 / 2 (white frequency noise), S_d = c^2 2 pi^2 h-2
// (random-walk frequency noise); the flicker term h-1 is left out as in their approximation. h: coefficients of
// the fractional-frequency PSD S_y(f) = h0 + h-2 / f^2 (h0 in s, h-2 in 1/s); clock PSDs in m^2/s and m^2/s^3.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>

#include "fusion/ins_error_model.hpp"
#include "signals/oscillator_allan.hpp"

namespace ultratrack::fusion {

// The oscillator and its presets are the signal layer's (signals/oscillator_allan.hpp): the simulator's clock
// and the filters' clock model come from the same coefficients.
using signals::oscillator_preset;
using signals::OscillatorAllan;

// The clock part of the error model (PSDs from h0, h-2; initial sigmas kept from `base`).
ClockNoiseModel clock_noise_from_allan(const OscillatorAllan& allan, const ClockNoiseModel& base = {});

// Closed-form discrete process noise of the two-state clock over dt (Brown & Hwang):
// [S_b dt + S_d dt^3/3, S_d dt^2/2; S_d dt^2/2, S_d dt].
Eigen::Matrix2d clock_process_noise(const ClockNoiseModel& clock, double dt_s);

}  // namespace ultratrack::fusion

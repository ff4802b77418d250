// SPDX-License-Identifier: GPL-3.0-or-later
#include "signals/oscillator_allan.hpp"

#include <cmath>
#include <numbers>

namespace ultratrack::signals {

std::optional<OscillatorAllan> oscillator_preset(const std::string& name) {
  if (name == "tcxo") return OscillatorAllan{2e-19, 2e-20};
  if (name == "ocxo") return OscillatorAllan{8e-20, 4e-23};
  return std::nullopt;
}

std::vector<std::string> oscillator_preset_names() { return {"tcxo", "ocxo"}; }

std::optional<OscillatorAllan> oscillator_signal_preset(const std::string& name) {
  // h0 = 2 f^2 L(f) / nu^2 at f = 1 kHz.
  const auto white_fm = [](double phase_noise_dbchz, double nominal_hz) {
    return 2.0 * 1e6 * std::pow(10.0, phase_noise_dbchz / 10.0) / (nominal_hz * nominal_hz);
  };
  const auto slow = oscillator_preset(name);
  if (!slow) return std::nullopt;
  OscillatorAllan a = *slow;
  a.h0 = name == "tcxo" ? white_fm(-135.0, 26e6) : white_fm(-150.0, 10e6);
  return a;
}

ReceiverClockModel receiver_clock_from_allan(const OscillatorAllan& allan) {
  constexpr double kPi2 = std::numbers::pi * std::numbers::pi;
  ReceiverClockModel m;
  m.bias_noise_s_per_sqrt_s = std::sqrt(allan.h0 / 2.0);
  m.drift_noise_sps_per_sqrt_s = std::sqrt(2.0 * kPi2 * allan.h_minus2);
  return m;
}

double allan_deviation(const OscillatorAllan& allan, double tau_s) {
  constexpr double kPi2 = std::numbers::pi * std::numbers::pi;
  return std::sqrt(allan.h0 / (2.0 * tau_s) + 2.0 * kPi2 / 3.0 * allan.h_minus2 * tau_s);
}

}  // namespace ultratrack::signals

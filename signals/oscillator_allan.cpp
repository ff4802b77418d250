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

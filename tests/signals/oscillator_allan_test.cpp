// SPDX-License-Identifier: GPL-3.0-or-later
// The simulated receiver clock of a named oscillator has the Allan deviation its power-law coefficients give in
// closed form (sigma_y^2(tau) = h0 / (2 tau) + (2 pi^2 / 3) h-2 tau): the synthesiser's clock noise is what
// the scenario's oscillator says, measured from the clock itself with the overlapping Allan estimator.
#include "signals/oscillator_allan.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "signals/receiver_clock.hpp"

namespace ultratrack::signals {
namespace {

// Overlapping Allan deviation from phase (time-error) samples x spaced tau0 apart, at tau = m tau0.
double overlapping_adev(const std::vector<double>& x, double tau0_s, std::size_t m) {
  double sum = 0.0;
  const std::size_t n = x.size() - 2 * m;
  for (std::size_t i = 0; i < n; ++i) {
    const double d = x[i + 2 * m] - 2.0 * x[i + m] + x[i];
    sum += d * d;
  }
  const double tau = static_cast<double>(m) * tau0_s;
  return std::sqrt(sum / (2.0 * tau * tau * static_cast<double>(n)));
}

TEST(OscillatorAllan, PresetsAreBrownAndHwangsTable) {
  EXPECT_DOUBLE_EQ(oscillator_preset("tcxo")->h0, 2e-19);
  EXPECT_DOUBLE_EQ(oscillator_preset("tcxo")->h_minus2, 2e-20);
  EXPECT_DOUBLE_EQ(oscillator_preset("ocxo")->h0, 8e-20);
  EXPECT_DOUBLE_EQ(oscillator_preset("ocxo")->h_minus2, 4e-23);
  EXPECT_FALSE(oscillator_preset("rubidium").has_value());
}

// Over 1000 s at the 1 ms grid: at tau <= 0.1 s there are >= 10^4 independent differences, at tau = 1 s ~10^3;
// across 12 seeds the estimate scattered up to 1 % (tau <= 0.1 s) and 2 % (1 s) about the closed form, so the
// 3 % and 6 % bounds are >= 3 sigma of the estimator (a wrong factor of 2 in either h is 40 % or more); the
// seed is fixed, so the test is deterministic.
TEST(OscillatorAllan, SimulatedClockHasTheClosedFormAllanDeviation) {
  for (const auto& allan :
       {*oscillator_preset("tcxo"), *oscillator_preset("ocxo"), *oscillator_signal_preset("tcxo")}) {
    const std::string name = "h0 " + std::to_string(allan.h0);
    ReceiverClock clock(receiver_clock_from_allan(allan), 7);
    const double tau0 = ReceiverClock::kGridStep_s;
    std::vector<double> x;
    for (std::size_t k = 0; k <= 1'000'000; ++k) x.push_back(clock.at(static_cast<double>(k) * tau0).bias_s);
    for (const auto& [m, tolerance] : {std::pair<std::size_t, double>{10, 0.03}, {100, 0.03}, {1000, 0.06}}) {
      const double tau = static_cast<double>(m) * tau0;
      const double expected = allan_deviation(allan, tau);
      EXPECT_NEAR(overlapping_adev(x, tau0, m) / expected, 1.0, tolerance) << name << " tau " << tau << " s";
    }
  }
}

// The signal presets' white frequency noise from the class phase noise at 1 kHz: h0 = 2 f^2 L / nu^2.
TEST(OscillatorAllan, SignalPresetsTakeWhiteFrequencyNoiseFromPhaseNoise) {
  EXPECT_NEAR(oscillator_signal_preset("tcxo")->h0, 2.0 * 1e6 * 3.1623e-14 / (26e6 * 26e6), 1e-26);
  EXPECT_NEAR(oscillator_signal_preset("ocxo")->h0, 2.0e-23, 1e-27);
  EXPECT_DOUBLE_EQ(oscillator_signal_preset("tcxo")->h_minus2, 2e-20);
  EXPECT_FALSE(oscillator_signal_preset("rubidium").has_value());
}

TEST(OscillatorAllan, TcxoAllanDeviationAtOneSecond) {
  // sqrt(1e-19 + 2 pi^2 / 3 * 2e-20) = 4.81e-10: a TCXO-class short-term stability.
  EXPECT_NEAR(allan_deviation(*oscillator_preset("tcxo"), 1.0), 4.81e-10, 0.01e-10);
}

}  // namespace
}  // namespace ultratrack::signals

// SPDX-License-Identifier: GPL-3.0-or-later
#include "test_signal.hpp"

#include <cmath>
#include <random>

#include "signals/ca_code.hpp"
#include "signals/gps_constants.hpp"

namespace ultratrack::test {

double amplitude(const TestSatellite& sat, const TestSignal& sig) {
  if (!sig.noise) return 1.0;
  return std::sqrt(2.0 * std::pow(10.0, sat.cn0_dbhz / 10.0) / sig.sample_rate_hz);
}

double true_doppler_hz(const TestSatellite& sat, double t) { return sat.doppler_hz + sat.doppler_rate_hzps * t; }

double true_carrier_phase_cycles(const TestSatellite& sat, double t) {
  return sat.carrier_phase_cycles + sat.doppler_hz * t + 0.5 * sat.doppler_rate_hzps * t * t;
}

double true_code_phase_chips(const TestSatellite& sat, double t) {
  // Code Doppler is the carrier Doppler scaled by f_chip / f_L1 (same range rate).
  const double carrier_cycles = sat.doppler_hz * t + 0.5 * sat.doppler_rate_hzps * t * t;
  return sat.code_phase_chips + signals::kCaChipRate_hz * t +
         carrier_cycles * signals::kCaChipRate_hz / signals::kL1Frequency_hz;
}

std::vector<std::complex<float>> generate(const std::vector<TestSatellite>& sats, const TestSignal& sig,
                                          std::int64_t first_sample, std::int64_t n) {
  std::vector<std::complex<float>> out(static_cast<std::size_t>(n));
  if (sig.noise) {
    std::mt19937_64 rng(sig.seed + static_cast<std::uint64_t>(first_sample) * 0x9E3779B97F4A7C15ull);
    std::normal_distribution<float> g(0.0f, 1.0f);
    for (auto& x : out) x = {g(rng), g(rng)};
  }
  for (const auto& sat : sats) {
    const auto& chips = signals::ca_code(sat.prn);
    const double a = amplitude(sat, sig);
    for (std::int64_t i = 0; i < n; ++i) {
      const double t = static_cast<double>(first_sample + i) / sig.sample_rate_hz;
      if (t < sat.start_s || t >= sat.stop_s) continue;
      const double code = true_code_phase_chips(sat, t);
      const double period = std::floor(code / signals::kCaCodeLength_chips);
      const int chip = static_cast<int>(code - period * signals::kCaCodeLength_chips);
      double value = chips[chip < 1023 ? chip : 1022];
      if (!sat.bits.empty()) {
        const auto k = static_cast<std::int64_t>(std::floor((period + sat.bit_offset_periods) / 20.0));
        const auto nb = static_cast<std::int64_t>(sat.bits.size());
        value *= sat.bits[static_cast<std::size_t>(((k % nb) + nb) % nb)];
      }
      const double phase =
          2.0 * M_PI * (true_carrier_phase_cycles(sat, t) - std::floor(true_carrier_phase_cycles(sat, t)));
      out[static_cast<std::size_t>(i)] += std::complex<float>(static_cast<float>(a * value * std::cos(phase)),
                                                              static_cast<float>(a * value * std::sin(phase)));
    }
  }
  return out;
}

}  // namespace ultratrack::test

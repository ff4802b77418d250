// SPDX-License-Identifier: GPL-3.0-or-later
// Test signal, written apart from the acquisition code: one or more GPS C/A signals at known code phase,
// Doppler (with the coherent code Doppler), C/N0 and data bits, in complex white Gaussian noise of unit
// power per sample (so N0 = 1 / fs and the carrier amplitude is sqrt(C/N0 / fs)).
#pragma once

#include <cmath>
#include <complex>
#include <cstdint>
#include <numbers>
#include <random>
#include <vector>

#include "signals/ca_code.hpp"

namespace ultratrack::test {

struct CaSignal {
  int prn = 1;
  double code_phase_chips = 0.0;  // code phase at sample 0
  double doppler_hz = 0.0;
  double cn0_dbhz = 45.0;
  double carrier_phase_rad = 0.3;
  double first_bit_edge_s = 0.0;  // data bit edges at this time + i * 20 ms
  std::vector<int> bits{1};       // +1/-1 per 20 ms bit, repeated cyclically
};

inline void add_ca_signal(std::vector<std::complex<float>>& samples, double fs_hz, const CaSignal& s) {
  const auto& code = signals::ca_code(s.prn);
  const double amplitude = std::sqrt(std::pow(10.0, s.cn0_dbhz / 10.0) / fs_hz);
  const double chip_rate = 1.023e6 * (1.0 + s.doppler_hz / 1575.42e6);
  for (std::size_t n = 0; n < samples.size(); ++n) {
    const double t = static_cast<double>(n) / fs_hz;
    const double phase = s.code_phase_chips + chip_rate * t;
    const auto chip = static_cast<long long>(std::floor(phase)) % 1023;
    const auto bit_index = static_cast<long long>(std::floor((t - s.first_bit_edge_s) / 0.020));
    const auto nbits = static_cast<long long>(s.bits.size());
    const int bit = s.bits[static_cast<std::size_t>(((bit_index % nbits) + nbits) % nbits)];
    const double carrier = 2.0 * std::numbers::pi * s.doppler_hz * t + s.carrier_phase_rad;
    samples[n] += static_cast<float>(amplitude * code[static_cast<std::size_t>(chip)] * bit) *
                  std::complex<float>(static_cast<float>(std::cos(carrier)), static_cast<float>(std::sin(carrier)));
  }
}

inline std::vector<std::complex<float>> complex_noise(std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<float> normal(0.0f, std::sqrt(0.5f));
  std::vector<std::complex<float>> samples(n);
  for (auto& x : samples) x = {normal(rng), normal(rng)};
  return samples;
}

}  // namespace ultratrack::test

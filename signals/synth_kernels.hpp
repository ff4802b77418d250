// SPDX-License-Identifier: GPL-3.0-or-later
// The per-sample inner loops of the IF synthesiser, kept apart so they can be benchmarked and reasoned
// about alone: code x carrier accumulation with a fixed-point code phase and a 4096-entry carrier table,
// Gaussian noise, and seeded random engines. No allocation, no exceptions.
#pragma once

#include <complex>
#include <cstddef>
#include <cstdint>
#include <random>

namespace ultratrack::signals::synth {

// A 64-bit Mersenne Twister seeded from the full 64-bit scenario seed and a stream number (so that the
// noise of each antenna, the clock, ... draw independent sequences from one seed).
std::mt19937_64 seeded_engine(std::uint64_t seed, std::uint64_t stream);

// out[i] += data * chip_amplitude[chip(i)] * exp(j 2 pi phase(i)) for i < count, where
// chip(i) = floor(code0_chips + i * code_rate) mod 1023 (code0_chips in [0, 1023)) and
// phase(i) = carrier0_cycles + i * carrier_rate (cycles). Real output adds only the real part.
void add_code_carrier(std::complex<float>* out, std::size_t count, const float* chip_amplitude, float data,
                      double code0_chips, double code_rate_chips_per_sample, double carrier0_cycles,
                      double carrier_rate_cycles_per_sample, bool real_output);

// Independent N(0, 1) values from a seeded engine: Marsaglia and Tsang's ziggurat (128 layers, exact
// tail and wedge sampling), one 64-bit draw per value with the layer and the value taken from separate
// bits (Doornik's remark on the original). The sequence does not depend on how samples are split into calls.
class GaussianNoise {
 public:
  GaussianNoise(std::uint64_t seed, std::uint64_t stream) : rng_(seeded_engine(seed, stream)) {}
  // out[i] = sigma * (x + j y); real output: y = 0.
  void fill(std::complex<float>* out, std::size_t count, float sigma, bool real_output);
  double next();  // one N(0, 1) value

 private:
  double slow_path(std::int32_t hz, int iz);
  double uniform();  // (0, 1)
  std::mt19937_64 rng_;
};

}  // namespace ultratrack::signals::synth

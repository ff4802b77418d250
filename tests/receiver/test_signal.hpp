// SPDX-License-Identifier: GPL-3.0-or-later
// Test signal generator for the receiver tests, written independently of the correlator and NCO code: each
// sample is computed from closed forms in double precision (C/A chips at a code rate that follows the Doppler,
// carrier phase with Doppler and Doppler rate, LNAV-rate data bits aligned to code periods, complex white
// Gaussian noise at a given C/N0). Complex baseband, noise sigma 1 per component.
#pragma once

#include <complex>
#include <cstdint>
#include <vector>

namespace ultratrack::test {

struct TestSatellite {
  int prn = 1;
  double cn0_dbhz = 45.0;             // carrier-to-noise density, dB-Hz (ignored when noise is off: amplitude 1)
  double doppler_hz = 0.0;            // carrier Doppler at sample 0
  double doppler_rate_hzps = 0.0;     // constant Doppler rate
  double code_phase_chips = 0.0;      // code phase at sample 0, chips (any value; period 0 starts at phase 0)
  double carrier_phase_cycles = 0.0;  // carrier phase at sample 0
  // Bit k spans code periods [20k - bit_offset_periods, 20k + 20 - bit_offset_periods); +1/-1 values,
  // repeated cyclically. Empty = no data modulation.
  std::vector<int> bits;
  int bit_offset_periods = 0;           // 0..19
  double start_s = 0.0, stop_s = 1e30;  // signal present only in [start_s, stop_s)
};

struct TestSignal {
  double sample_rate_hz = 4e6;
  bool noise = true;
  std::uint64_t seed = 1;
};

// Amplitude of a satellite in the generator's units (noise sigma 1 per component): C/N0 = A^2 fs / 2.
double amplitude(const TestSatellite& sat, const TestSignal& sig);
// Truth: carrier phase (cycles) and code phase (chips, continuous) at time t = sample / fs.
double true_carrier_phase_cycles(const TestSatellite& sat, double t);
double true_code_phase_chips(const TestSatellite& sat, double t);
double true_doppler_hz(const TestSatellite& sat, double t);

// Samples [first_sample, first_sample + n) of the sum of the satellites plus noise.
std::vector<std::complex<float>> generate(const std::vector<TestSatellite>& sats, const TestSignal& sig,
                                          std::int64_t first_sample, std::int64_t n);

}  // namespace ultratrack::test

// SPDX-License-Identifier: GPL-3.0-or-later
// CorrelationEpoch: what a tracking channel returns for one coherent integration (1 code period = 1 ms, or 20
// after bit sync): complex correlator sums per antenna and the replica's state at the epoch's start and end
// (code phase in chips, carrier phase in cycles, rates in chips/s and Hz), as the observables need them.
#pragma once

#include <array>
#include <complex>
#include <cstdint>

namespace ultratrack::receiver {

inline constexpr int kMaxAntennas = 4;

// Correlator sums of one antenna: sum over the epoch's samples of x[i] * code(tap phase) * exp(-j carrier phase).
// For a clean signal A exp(j phi) aligned with the replica the prompt is A * N (N = samples in the epoch),
// so the sums are unnormalised: divide by N for amplitude. Taps that are disabled read zero.
struct CorrelatorTaps {
  std::complex<float> very_early{}, early{}, prompt{}, late{}, very_late{};
  // Off-peak replica (same PRN, shifted to a lag where the code's autocorrelation is -1/1023): noise only.
  std::complex<float> noise{};
};

struct CorrelationEpoch {
  int prn = 0;
  std::int64_t first_sample = 0;  // receiver sample index of the epoch's first sample
  int num_samples = 0;
  double integration_time_s = 0.0;  // num_samples / fs
  // Code periods spanned: the epoch starts where the replica code phase crosses the start of period
  // first_code_period (periods counted by the channel since its start) and lasts num_code_periods periods.
  std::int64_t first_code_period = 0;
  int num_code_periods = 1;

  int num_antennas = 1;
  std::array<CorrelatorTaps, kMaxAntennas> antenna{};  // antenna[0] is the master antenna
  // Prompt of the master antenna over the first and second half of the epoch (their sum is antenna[0].prompt);
  // the halves never straddle a navigation-bit edge, so a frequency discriminator can use them before bit sync.
  std::array<std::complex<float>, 2> prompt_halves{};

  // Replica state. Code phase is measured from the start of code period first_code_period, chips: the start
  // value is within one sample step of 0 (or the commanded jump), the end value near 1023 * num_code_periods.
  double code_phase_start_chips = 0.0;
  double code_phase_end_chips = 0.0;
  double code_rate_chips_per_s = 0.0;
  // Carrier phase accumulated since the channel started (continuous, cycles) and the replica frequency, Hz.
  double carrier_phase_start_cycles = 0.0;
  double carrier_phase_end_cycles = 0.0;
  double carrier_frequency_hz = 0.0;

  const CorrelatorTaps& master() const { return antenna[0]; }
};

}  // namespace ultratrack::receiver

// SPDX-License-Identifier: GPL-3.0-or-later
// Test-only brute-force fine search of one satellite in complex baseband samples: time-domain correlation
// with a fractional-delay C/A replica (no FFT, no receiver code), code phase by an early-late amplitude
// balance on the correlation triangle, Doppler from the carrier-phase progression of code-aligned 1 ms
// correlations (squared, so data bits do not matter). Code phase in chips at sample 0 (the chip being
// received at the first sample, [0, 1023)); Doppler in Hz of the baseband signal I + jQ, mean over the span.
#pragma once

#include <complex>
#include <span>

namespace ultratrack::test {

struct FineSearchResult {
  double doppler_hz = 0.0;
  double code_phase_chips = 0.0;    // at sample 0, [0, 1023)
  double peak_amplitude = 0.0;      // rms of the 1 ms correlations at the estimate
  double off_peak_amplitude = 0.0;  // the same half a code period away (cross-correlation and noise floor)
};

// Searches code phase within code_hint_chips +- 1.5 chips and Doppler within about +-200 Hz of
// doppler_hint_hz, over all whole code periods in `samples` (sampled at fs_hz).
FineSearchResult brute_force_fine_search(std::span<const std::complex<float>> samples, double fs_hz, int prn,
                                         double doppler_hint_hz, double code_hint_chips);

}  // namespace ultratrack::test

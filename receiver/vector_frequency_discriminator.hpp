// SPDX-License-Identifier: GPL-3.0-or-later
// The carrier frequency discriminator a vector loop reads from a channel (vector DLL/FLL, issue 7): two
// contiguous correlation epochs of length T (20 ms after bit sync) whose middles are dt apart; the change of their
// Costas phases (bit-insensitive) over dt, plus the replica's mean frequency, is the signal's mean frequency over
// that interval. The phase change is taken within +-1/4 cycle, so the discriminator's range is +-1 / (4 dt) (+-12.5
// Hz at 20 ms): the FLL mode (carrier NCO commanded from the filter's predicted Doppler) must keep the replica's
// frequency error well inside it. Units: cycles, Hz, seconds; C/N0 as a ratio in Hz.
#pragma once

#include <complex>

namespace ultratrack::receiver {

// Change of the Costas phase from `first` to `second` (the signal's phase minus the replica's), cycles in
// (-1/4, 1/4]: the data bit (a half cycle) between the two is removed.
double costas_phase_change_cycles(std::complex<float> first, std::complex<float> second);

// The same change with the data bits wiped (both epochs' bits known: sign_product = the product of their signs,
// +1 or -1): the full phase of conj(first) x second x sign_product, cycles in (-1/2, 1/2], so the range is
// +-1 / (2 dt) (+-25 Hz at 20 ms) and, unlike the Costas arctangent's, the output is not pulled toward 0 by the
// noise: in a Monte Carlo (f0 = 3 Hz, T = dt = 20 ms) its mean is 0.99 / 0.95 / 0.85 x f0 at 22 / 20 / 18 dB-Hz
// where the Costas change's is 0.78 / 0.56 / 0.33 x f0 (noise reaching its +-1/4 cycle wrap). A loop reading the
// Costas change at those levels sees its own prediction's frequency more than the signal's.
double wiped_phase_change_cycles(std::complex<float> first, std::complex<float> second, int sign_product);

// Closed-form variance (Hz^2) of that discriminator's frequency for epochs of t_s at cn0_hz, middles dt_s apart:
// 2 sigma_phi^2 / dt^2 with the Costas arctangent's per-epoch phase variance sigma_phi^2 = 1 / (2 T C/N0)
// (1 + 1 / (2 T C/N0)) rad^2 (Kaplan & Hegarty, ch. 5, with Bn = 1 / (2 T): one independent output per epoch) in
// cycles^2. The two epochs' noises are independent; consecutive outputs share an epoch (correlation -1/2).
// Within 5 % of a Monte Carlo of costas_phase_change_cycles from 25 to 45 dB-Hz at 20 ms (tests/receiver/
// vector_fll_test.cpp); at 25 dB-Hz the output's mean is pulled ~3 % toward 0 by noise reaching the wrap.
// For the wiped change (no squaring loss, its linear variance would be 2 / (2 T C/N0) rad^2 / dt^2) the same form
// holds within -2 / +17 % from 18 to 45 dB-Hz (Monte Carlo: 1.07 / 1.16-1.17 / 1.12 / 1.05 at 18 / 20 / 22 / 24
// dB-Hz, 0.98-1.03 from 26 up): the (1 + 1 / (2 T C/N0)) term stands for the arctangent's non-linear tails there.
double phase_change_frequency_variance_hz2(double cn0_hz, double t_s, double dt_s);

}  // namespace ultratrack::receiver

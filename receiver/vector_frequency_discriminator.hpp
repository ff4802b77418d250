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

// Closed-form variance (Hz^2) of that discriminator's frequency for epochs of t_s at cn0_hz, middles dt_s apart:
// 2 sigma_phi^2 / dt^2 with the Costas arctangent's per-epoch phase variance sigma_phi^2 = 1 / (2 T C/N0)
// (1 + 1 / (2 T C/N0)) rad^2 (Kaplan & Hegarty, ch. 5, with Bn = 1 / (2 T): one independent output per epoch) in
// cycles^2. The two epochs' noises are independent; consecutive outputs share an epoch (correlation -1/2).
// Within 5 % of a Monte Carlo of costas_phase_change_cycles from 25 to 45 dB-Hz at 20 ms (tests/receiver/
// vector_fll_test.cpp); at 25 dB-Hz the output's mean is pulled ~3 % toward 0 by noise reaching the wrap.
double phase_change_frequency_variance_hz2(double cn0_hz, double t_s, double dt_s);

}  // namespace ultratrack::receiver

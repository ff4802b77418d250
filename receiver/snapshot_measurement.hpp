// SPDX-License-Identifier: GPL-3.0-or-later
// Snapshot measurements: every visible satellite's fine code phase and Doppler from one short block of
// complex baseband samples (tens to hundreds of ms), for coarse-time navigation (receiver/snapshot_navigation.hpp).
//
// 1. Acquisition (receiver/acquisition.hpp) of every PRN over the snapshot: coherent blocks of T_coh =
//    10 ms (5 ms below 40 ms of signal) summed non-coherently over the whole snapshot, with cancellation of
//    the strong signals' cross-correlations, on sums of fs / 4 MHz samples when fs >= 8 MHz (the search's cost
//    grows with fs^2 log fs). Its fine Doppler and code phase seed step 2.
// 2. Fine code phase by a non-coherent early-minus-late loop over the whole snapshot, run to convergence: per
//    coherent block the early and late correlations (spacing d chips) at the acquisition Doppler, the replica's
//    code rate scaled by that Doppler; amplitudes with the noise power (a lag half a code period away)
//    removed; tau += (1 - d / 2) (L - E) / (E + L), five times (a front end's filter rounds the peak and
//    lowers the gain near it: the repetitions converge anyway). The code phase at the first sample is the result.
// 1-sigma of the code phase: the non-coherent early-late discriminator's thermal noise (Kaplan & Hegarty,
// 3rd ed., eq. 8.48 without band limiting), sigma^2 = d / (4 C/N0 T) (1 + 2 / ((2 - d) C/N0 T_coh)), with
// T the snapshot length; of the Doppler: the acquisition's fine-search resolution, step / 8, with a floor from
// the C/N0. Units: chips, Hz, dB-Hz, seconds.
#pragma once

#include <complex>
#include <span>
#include <string>
#include <vector>

namespace ultratrack::receiver {

struct SnapshotSearchOptions {
  double fs_hz = 0.0;
  double doppler_max_hz = 5000.0;  // search +-, receiver oscillator offset included
  double pfa = 1e-3;               // per PRN search
  int coherent_ms = 0;             // 0: 10 ms, or 5 ms for snapshots shorter than 40 ms
  double spacing_chips = 0.5;      // early-late spacing d of the fine code loop, (0, 1.5]
  // A detection is kept when its metric is at least min_metric_ratio times the threshold, or its C/N0 within
  // cross_correlation_margin_db of the strongest detection's: a snapshot fix depends on every measurement, and on
  // real recordings detections just over the threshold and far below the strongest are mostly spurs and
  // cross-correlations (pocketsdr_L1_12MHz: 17 of them at 1.0-1.7 x, 16-20 dB below the strongest; Gold-code
  // cross-correlations are 21-24 dB down).
  double min_metric_ratio = 2.0;
  double cross_correlation_margin_db = 10.0;

  bool IsValid(std::string* error) const;
};

struct SnapshotDetection {
  int prn = 0;
  double code_phase_chips = 0.0;  // at the snapshot's first sample, [0, 1023)
  double code_sigma_chips = 0.0;
  double doppler_hz = 0.0;
  double doppler_sigma_hz = 0.0;
  double cn0_dbhz = 0.0;
  double acquisition_metric = 0.0, acquisition_threshold = 0.0;
};

// The detected satellites among `prns` in samples (the whole snapshot; at least 2 coherent blocks). Throws
// std::invalid_argument when the options are not valid or the snapshot is shorter than 2 blocks.
std::vector<SnapshotDetection> measure_snapshot(std::span<const std::complex<float>> samples,
                                                const std::vector<int>& prns, const SnapshotSearchOptions& options);

}  // namespace ultratrack::receiver

// SPDX-License-Identifier: GPL-3.0-or-later
// Carrier-smoothed pseudoranges (Hatch filter) for the PVT: the code's thermal noise (DLL jitter, ~1 m at
// 45 dB-Hz with 1 chip E-L spacing) averaged against the carrier's millimetre-level phase changes:
//     P_s(k) = P(k) / n + (n - 1) / n * (P_s(k-1) + lambda (L(k) - L(k-1))),  n = min(k, window)
// with L in RINEX sense (cycles, grows with range). The raw pseudoranges still go to RINEX; only the PVT sees
// the smoothed ones. Restarts on a new track (loss of lock), on a jump of the code-minus-carrier beyond
// a threshold, and after a gap. The threshold is max(slip_threshold_m, 6 code_sigma_m): a gross jump (a
// carrier count off by hundreds of cycles, a code or time-tag slip), never the code's own noise. (A fixed 20 m
// was 2.3 sigma of the DLL noise at 28 dB-Hz: the filter restarted every ~3 s at 28 dB-Hz, every ~1.3 s at 26,
// and the PVT saw nearly raw pseudoranges.) A cycle slip (0.19 m) is far below any code-based test: the
// tracking loop's lock detectors report it as a new track. The ionosphere makes code and carrier
// diverge at twice its rate (<= ~0.1 m over a 10 s window at mid latitudes), which bounds the window.
// Units: metres, cycles, seconds.
#pragma once

#include <array>
#include <cstdint>

namespace ultratrack::receiver {

class CarrierSmoothing {
 public:
  explicit CarrierSmoothing(int window_epochs = 100, double slip_threshold_m = 20.0)
      : window_(window_epochs), slip_threshold_m_(slip_threshold_m) {}

  // One epoch of one PRN; returns the smoothed pseudorange. epoch_index counts observation epochs (a gap in it
  // restarts the filter).
  // code_sigma_m: the pseudorange's expected thermal noise (1 sigma, e.g. dll_thermal_jitter_chips at the
  // measured C/N0), 0 when unknown (the fixed threshold alone).
  double update(int prn, std::int64_t epoch_index, double pseudorange_m, double carrier_phase_cycles, bool new_track,
                double code_sigma_m = 0.0);
  // The receiver clock jumped by dt_s (its reading decreased by dt_s): every pseudorange drops by c dt_s.
  void clock_jump(double dt_s);

 private:
  struct State {
    std::int64_t last_epoch = -2;
    int n = 0;
    double smoothed_m = 0.0;
    double last_phase_cycles = 0.0;
  };
  int window_;
  double slip_threshold_m_;
  std::array<State, 33> state_{};
};

}  // namespace ultratrack::receiver

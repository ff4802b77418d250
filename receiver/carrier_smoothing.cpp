// SPDX-License-Identifier: GPL-3.0-or-later
#include "receiver/carrier_smoothing.hpp"

#include <algorithm>
#include <cmath>

#include "signals/gps_constants.hpp"

namespace ultratrack::receiver {
namespace {
// A jump is a code-minus-carrier step beyond 6 sigma of the code noise: 2e-9 per epoch for Gaussian noise, still
// 6e-7 when the C/N0 estimate behind sigma reads 1.5 dB (its 0.2 s spread) high.
constexpr double kJumpSigmas = 6.0;
}  // namespace

double CarrierSmoothing::update(int prn, std::int64_t epoch_index, double pseudorange_m, double carrier_phase_cycles,
                                bool new_track, double code_sigma_m) {
  State& s = state_[static_cast<std::size_t>(prn)];
  const double predicted = s.smoothed_m + signals::kL1Wavelength_m * (carrier_phase_cycles - s.last_phase_cycles);
  const bool restart = new_track || s.n == 0 || epoch_index != s.last_epoch + 1 ||
                       std::abs(pseudorange_m - predicted) > std::max(slip_threshold_m_, kJumpSigmas * code_sigma_m);
  if (restart) {
    s.n = 1;
    s.smoothed_m = pseudorange_m;
  } else {
    s.n = std::min(s.n + 1, window_);
    s.smoothed_m = pseudorange_m / s.n + (s.n - 1.0) / s.n * predicted;
  }
  s.last_epoch = epoch_index;
  s.last_phase_cycles = carrier_phase_cycles;
  return s.smoothed_m;
}

void CarrierSmoothing::clock_jump(double dt_s) {
  for (State& s : state_) s.smoothed_m -= signals::kSpeedOfLight_mps * dt_s;
}

}  // namespace ultratrack::receiver

// SPDX-License-Identifier: GPL-3.0-or-later
// The ultra-tight I&Q model's signal power of one channel (pipelines/ultratight_loop.hpp). Units: taps on the raw
// correlator scale; A^2 on the unit-noise scale.
#pragma once

#include <algorithm>
#include <cmath>

namespace ultratrack::pipelines {

// The I&Q model's signal power of one channel from the prompt taps: running means of I_P^2 + Q_P^2 on the raw
// scale (taps / iq_scale, so the per-epoch noise normalisation does not move it), E[I_P^2 + Q_P^2] = A^2 + 2 in
// unit-noise taps. Two means: ~0.2 s (weight 0.1) follows a C/N0 step, ~1 s (weight 0.02) is the one used while
// the two agree; the slow one restarts from the fast one when they differ by more than 3 of the fast one's
// sigmas, sqrt((4 + 4 A^2) 0.1 / 1.9). Why 1 s: at 16 dB-Hz (A^2 = 1.59) the 0.2 s mean's A^2 has a standard
// deviation of 0.74 (46 %), and a C/N0 gate on it selects the epochs that read high (docs/validation.md).
struct PromptPowerAverage {
  double fast = NAN, slow = NAN;  // raw scale
  // p2_raw: this epoch's I_P^2 + Q_P^2 on the raw scale; scale2 = iq_scale^2. Returns A^2 on this epoch's unit-noise
  // scale from the epochs before this one (this epoch's own noise would otherwise enter its prediction), then
  // takes this epoch in. The first epoch uses itself.
  double update(double p2_raw, double scale2) {
    const double f = std::isfinite(fast) ? fast : p2_raw;
    double s = std::isfinite(slow) ? slow : f;
    const double fast_sigma = std::sqrt((4.0 + 4.0 * std::max(0.0, f * scale2 - 2.0)) * 0.1 / 1.9);
    if (std::abs(s - f) * scale2 > 3.0 * fast_sigma) s = f;
    fast = f + 0.1 * (p2_raw - f);
    slow = s + 0.02 * (p2_raw - s);
    return s * scale2 - 2.0;
  }
};

}  // namespace ultratrack::pipelines

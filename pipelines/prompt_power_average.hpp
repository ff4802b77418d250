// SPDX-License-Identifier: GPL-3.0-or-later
// The ultra-tight I&Q model's signal power of one channel (pipelines/ultratight_loop.hpp). Units: taps on the raw
// correlator scale; A^2 on the unit-noise scale.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>

namespace ultratrack::pipelines {

// The I&Q model's signal power of one channel from the prompt taps: running means of I_P^2 + Q_P^2 on the raw
// scale (taps / iq_scale, so the per-epoch noise normalisation does not move it), E[I_P^2 + Q_P^2] = A^2 + 2 in
// unit-noise taps. Two means: ~0.2 s (weight 0.1) follows a C/N0 step, ~1 s (weight 0.02) is the one used while
// the two agree; the slow one restarts when they differ by more than 4 of the fast one's sigmas,
// sqrt((4 + 4 A^2) 0.1 / 1.9) (at 3, the false restarts to the noisier window below spread A^2 by 15 % more than the
// 1 s mean's at 18 dB-Hz; a step worth a restart, e.g. 45 to 20 dB-Hz, is hundreds of sigmas). Why 1 s: at 16 dB-Hz
// (A^2 = 1.59) the 0.2 s mean's A^2 has a standard deviation of 0.74 (46 %), and a C/N0 gate on it selects the epochs
// that read high (docs/validation.md). A restart takes both means to the plain mean of the last kFastEpochs epochs (0.2
// s), not to the fast running mean: after 45 dB-Hz that keeps 0.9^n of the old power, still A^2 ~ 1 (14 dB-Hz, the I&Q
// update's coasting gate) 1.4 s into a tunnel, where the filter took noise as a 14 dB-Hz signal, and A^2 ~ 80 (A 4.5
// times 20 dB-Hz's) when the fade gate first let a 20 dB-Hz epoch through after a step. The window forgets the old
// level in 0.2 s.
struct PromptPowerAverage {
  static constexpr int kFastEpochs = 10;
  double fast = NAN, slow = NAN;             // raw scale
  std::array<double, kFastEpochs> recent{};  // raw scale, a ring of the latest epochs
  int count = 0, next = 0;

  double window_mean() const {
    double sum = 0.0;
    for (int k = 0; k < count; ++k) sum += recent[static_cast<std::size_t>(k)];
    return sum / count;
  }
  // p2_raw: this epoch's I_P^2 + Q_P^2 on the raw scale; scale2 = iq_scale^2. Returns A^2 on this epoch's unit-noise
  // scale from the epochs before this one (this epoch's own noise would otherwise enter its prediction), then
  // takes this epoch in. The first epoch uses itself.
  double update(double p2_raw, double scale2) {
    double f = std::isfinite(fast) ? fast : p2_raw;
    double s = std::isfinite(slow) ? slow : f;
    const double fast_sigma = std::sqrt((4.0 + 4.0 * std::max(0.0, f * scale2 - 2.0)) * 0.1 / 1.9);
    if (std::abs(s - f) * scale2 > 4.0 * fast_sigma) s = f = count > 0 ? window_mean() : f;
    fast = f + 0.1 * (p2_raw - f);
    slow = s + 0.02 * (p2_raw - s);
    recent[static_cast<std::size_t>(next)] = p2_raw;
    next = (next + 1) % kFastEpochs;
    count = std::min(count + 1, kFastEpochs);
    return s * scale2 - 2.0;
  }
};

}  // namespace ultratrack::pipelines

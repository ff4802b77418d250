// SPDX-License-Identifier: GPL-3.0-or-later
// A sudden fade of a strong channel's signal, seen within an epoch: a blockage (a tunnel, an overpass, a building
// edge) takes the prompt from C/N0 T times the noise power to the noise power at once, while the C/N0 estimate
// (a 0.2 s window) and the loss-of-lock test (low C/N0 or PLI held for its loss time) take tenths of a second to
// seconds to follow. In that time the loops run on noise and the code phase walks off by tens of metres, which a
// PVT (every satellite fades together, so RAIM sees no outlier) or a tight filter (every row off at once) takes as
// measurements. The channel's measurements are withheld from the first faded epoch on.
// Test, per epoch of length T with the channel's C/N0 estimate giving SNR = C/N0 T >= min_snr: faded when
// |P|^2 < fade_ratio * the running mean of |P|^2 (mean ~ N0' (1 + SNR), N0' the noise power per epoch).
// Thermal noise alone cannot make it: the amplitude must fall to sqrt(fade_ratio) = 0.32 of its mean, a noise
// excursion of (1 - 0.32) sqrt(2 SNR) sigma = 6.8 sigma at SNR 50 (about 1e-11 per epoch). A blocked signal leaves
// noise, whose power exceeds the threshold with probability exp(-fade_ratio (1 + SNR)) = 0.6 % per epoch at
// SNR 50 (a 20 ms epoch at 34 dB-Hz). Weaker channels are not tested (their fades are within noise).
// The fade ends after recover_epochs epochs in a row above the threshold (the reference frozen meanwhile), or when a
// presence test (receiver/presence_test.hpp: prompt against noise-tap power over present_window_s) finds the signal
// still there at present_dbhz or more: a step down of the C/N0, not a blockage (the mean restarts at the new level).
// A fade that lasts is for the loss-of-lock test to end (the track is then lost and re-acquired).
#pragma once

#include <complex>
#include <optional>

#include "receiver/presence_test.hpp"

namespace ultratrack::receiver {

struct FadeDetectorOptions {
  double min_snr = 50.0;          // C/N0 T below this: not tested (34 dB-Hz at 20 ms)
  double fade_ratio = 0.1;        // |P|^2 below this fraction of its mean: faded (a 10 dB drop in one epoch)
  int recover_epochs = 5;         // epochs in a row above the threshold that end a fade
  double reference_time_s = 0.5;  // the mean's time constant; tested once this much of the current epoch length ran
  // The presence test during a fade: windows of present_window_s, "present" at or above present_dbhz. At 20 ms
  // (25 epochs) noise alone reads present with probability 2e-4 per window (presence_absent_probability); a
  // signal at 25 dB-Hz reads absent with probability < 1e-5.
  double present_window_s = 0.5;
  double present_dbhz = 20.0;
};

class FadeDetector final {
 public:
  explicit FadeDetector(FadeDetectorOptions options = {}) : opt_(options), presence_(1, options.present_dbhz) {}
  // One epoch: its prompt and noise-tap sums, the channel's C/N0 estimate (dB-Hz, none before its first window), its
  // length (s). Epochs of another length than the previous (1 ms -> 20 ms at bit sync) restart the mean.
  void add(std::complex<float> prompt, std::complex<float> noise, std::optional<double> cn0_dbhz, double t_s);
  bool faded() const { return faded_; }
  long long fades() const { return fades_; }  // fades begun so far

 private:
  FadeDetectorOptions opt_;
  double epoch_s_ = 0.0;      // the length the mean is for
  double mean_power_ = 0.0;   // running mean of |P|^2 over epochs of that length
  double mean_time_s_ = 0.0;  // time the mean has run
  bool faded_ = false;
  SignalPresenceTest presence_;  // runs during a fade
  int above_ = 0;                // epochs in a row above the threshold during a fade
  long long fades_ = 0;
};

}  // namespace ultratrack::receiver

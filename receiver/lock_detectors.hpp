// SPDX-License-Identifier: GPL-3.0-or-later
// Lock detectors on prompt (and noise-tap) correlator sums: the phase lock indicator cos(2 dphi) from low-passed
// narrow-band difference and wide-band power, and C/N0 estimators (moments method; noise-tap power ratio) averaged
// over a window of epochs. Pure algorithms: no knowledge of channels or loops. C/N0 in dB-Hz at this edge.
#pragma once

#include <complex>
#include <optional>

namespace ultratrack::receiver {

// Phase lock indicator: PLI = LP(I^2 - Q^2) / LP(I^2 + Q^2 - Pn) -> cos(2 dphi), where LP is a first-order
// low-pass with the given time constant and Pn the noise power per epoch (0 if unknown: the PLI is then biased
// toward 0 by SNR / (SNR + 1), SNR = C/N0 * T). 1 = locked, 0 = no lock (noise), -1 = locked on the quadrature.
class PhaseLockIndicator final {
 public:
  explicit PhaseLockIndicator(double time_constant_s) : tau_s_(time_constant_s) {}
  // prompt: one epoch's prompt sum; noise_power: E|noise sum|^2 for the same epoch length; t_s: epoch length.
  double update(std::complex<float> prompt, double noise_power, double t_s);
  double value() const { return value_; }
  void reset() {
    narrow_ = wide_ = 0.0;
    value_ = 0.0;
    started_ = false;
  }
  // A new low-pass time constant (e.g. for longer epochs); the state is kept.
  void set_time_constant(double time_constant_s) { tau_s_ = time_constant_s; }

 private:
  double tau_s_;
  double narrow_ = 0.0, wide_ = 0.0, value_ = 0.0;
  bool started_ = false;
};

enum class Cn0Method {
  kMoments,   // second and fourth moments of the prompt (Matosevic et al. / Pauluzzi-Beaulieu): no extra tap
  kNoiseTap,  // prompt power over the noise tap's power: needs the noise correlator, robust at low C/N0
};

// Block-averaged C/N0 estimator: after every `window_epochs` epochs of equal length t_s returns a new estimate.
class Cn0Estimator final {
 public:
  Cn0Estimator(Cn0Method method, int window_epochs) : method_(method), window_(window_epochs) {}
  // Returns an estimate (dB-Hz) when a window completes. A window with no measurable signal gives kNoSignalDbHz.
  std::optional<double> add(std::complex<float> prompt, std::complex<float> noise, double t_s);
  void reset() {
    n_ = 0;
    m2_ = m4_ = noise_ = 0.0;
  }
  static constexpr double kNoSignalDbHz = 0.0;

 private:
  Cn0Method method_;
  int window_;
  int n_ = 0;
  double m2_ = 0.0, m4_ = 0.0, noise_ = 0.0;
};

}  // namespace ultratrack::receiver

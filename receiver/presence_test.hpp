// Signal-presence test for a channel whose replica an external filter drives (ultra-tight): over non-overlapping
// windows of n epochs, the prompt's power against the noise tap's, SNR_hat = sum|P|^2 / sum|N|^2 - 1 (per epoch);
// "absent" when SNR_hat < 10^(threshold_dbhz / 10) T. Energy only (no phase lock needed: the filter, not the
// PLL, keeps the replica on the signal). Exact error rates: docs/validation.md (Poisson mixture of beta laws).
#pragma once

#include <complex>
#include <optional>

namespace ultratrack::receiver {

class SignalPresenceTest final {
 public:
  // window_epochs >= 1; threshold in dB-Hz (converted with each epoch's length t_s).
  SignalPresenceTest(int window_epochs, double threshold_dbhz);
  // One epoch's prompt and noise-tap sums (same scale). Returns the verdict when a window completes (true:
  // present), nothing otherwise. Epochs of another length (by more than 1 %: the sample count of one length varies
  // with the code Doppler) than the window's first restart the window.
  std::optional<bool> add(std::complex<float> prompt, std::complex<float> noise, double t_s);
  void reset() { n_ = 0; prompt_power_ = noise_power_ = 0.0; t_s_ = 0.0; }
  // The latest completed window's SNR per epoch, as C/N0 (dB-Hz; -inf-like -100 when not positive).
  double last_cn0_dbhz() const { return last_cn0_dbhz_; }

 private:
  int window_;
  double threshold_dbhz_;
  int n_ = 0;
  double prompt_power_ = 0.0, noise_power_ = 0.0, t_s_ = 0.0;
  double last_cn0_dbhz_ = -100.0;
};

}  // namespace ultratrack::receiver

// SPDX-License-Identifier: GPL-3.0-or-later
// Pull-in of a scalar channel from the acquisition's frequency to the Costas PLL's lock-in range
// (ScalarTrackingOptions, pull-in): either a frequency search on the first 1 ms prompts with the carrier held,
// or a wide FLL (halves of each code period) then a narrow one (successive prompts); then a fine FLL on 5 ms
// prompt sums; then the PLL, which ScalarTracking runs and judges. Also the channel's frequency discriminator:
// cross and dot averaged over ~4 epochs, reported on every epoch. Units: Hz, seconds since the channel's start.
#pragma once

#include <array>
#include <complex>

#include "receiver/correlation_epoch.hpp"
#include "receiver/discriminators.hpp"
#include "receiver/loop_filters.hpp"
#include "receiver/scalar_tracking_options.hpp"

namespace ultratrack::receiver {

// The pull-in stage a time since the channel's start falls in (kPll: after the FLL stages; the PLL alone).
enum class PullInStage { kSearch, kWideFll, kNarrowFll, kFineFll, kPll };

class PullIn final {
 public:
  // options valid; initial_frequency_hz: the carrier NCO's frequency from acquisition.
  PullIn(const ScalarTrackingOptions& options, double initial_frequency_hz);

  PullInStage stage(double time_s) const;
  // When the PLL starts (the end of the fine FLL), s since the channel's start.
  double pll_start_s() const { return pll_start_s_; }

  // The frequency error of this epoch (Hz, the FLL discriminator):
  // cross and dot averaged over ~4 epochs, of this epoch's halves in the wide stage (and on the first epoch),
  // of this and the previous prompt (dot sign removed: bit-tolerant) afterwards. time_s: after this epoch.
  double frequency_error_hz(const CorrelationEpoch& e, double time_s);

  // One epoch of a stage before kPll (time_s: after this epoch): the carrier frequency of the next command (Hz),
  // driving `carrier` as the stage does. *frequency_error_hz holds this epoch's discriminator on entry (the
  // wide and narrow FLLs use it); the search at its end and the fine FLL at each 5 ms sum replace it with
  // their own estimate.
  double step(PullInStage stage, const CorrelationEpoch& e, double time_s, CarrierLoopFilter& carrier,
              double* frequency_error_hz);

 private:
  double search_frequency_offset_hz() const;
  double fine_fll(std::complex<float> prompt, double t_s, CarrierLoopFilter& carrier, double* frequency_error_hz);

  static constexpr int kMaxSearchEpochs = 500;

  ScalarTrackingOptions opt_;
  double initial_frequency_hz_ = 0.0;
  // stage ends (s since the channel's start)
  double search_end_s_ = 0.0, wide_end_s_ = 0.0, narrow_end_s_ = 0.0, pll_start_s_ = 0.0;
  std::array<std::complex<float>, kMaxSearchEpochs> search_prompts_{};
  int search_count_ = 0;
  std::complex<double> fine_sum_{}, fine_previous_{};
  int fine_count_ = 0;
  double fine_time_s_ = 0.0;
  bool fine_have_previous_ = false;
  // frequency discriminator
  std::complex<float> previous_prompt_{};
  CrossDot fll_average_{};
  bool wide_fll_ = true;
  double previous_t_s_ = 0.0;
};

}  // namespace ultratrack::receiver

// SPDX-License-Identifier: GPL-3.0-or-later
// Long coherent integration with data wipe-off (ScalarTrackingOptions, long coherent integration): the choice of
// N (1, 2, 5, 10, 20 epochs of 20 ms) from the C/N0, the block of N sign-corrected 20 ms epochs summed, the
// loops' settings for updates every N x 20 ms, and the carrier loop's frequency state re-referenced when N
// changes. ScalarTracking decides when a block runs (bits known, bit-synced, no commanded carrier) and runs the
// loops on its sums. Units: Hz, seconds; N in 20 ms epochs.
#pragma once

#include <complex>
#include <cstdint>

#include "receiver/correlation_epoch.hpp"
#include "receiver/lock_detectors.hpp"
#include "receiver/loop_filters.hpp"
#include "receiver/scalar_tracking_options.hpp"

namespace ultratrack::receiver {

// Thermal phase jitter of a Costas PLL, radians: sqrt(Bn / c (1 + 1 / (2 T c))), c = 10^(cn0_dbhz / 10).
double pll_thermal_jitter_rad(double bn_hz, double t_s, double cn0_dbhz);
// Phase jitter an oscillator puts into a PLL of noise bandwidth bn_hz and order 2 or 3 at L1, radians (linear
// theory, the analogue loop of loop_filters.hpp): the loop's error response to the clock's phase integrated
// in closed form, sigma^2 = q_w I_w / w0 + q_rw I_rw / w0^3 with q_w = (2 pi f_L1)^2 h0 / 2 (white frequency,
// rad^2/s), q_rw = (2 pi f_L1)^2 2 pi^2 h-2 (random-walk frequency, rad^2/s^3), w0 = Bn / (Bn per w0) and, for
// D(s) = s^3 + 2.4 s^2 + 1.1 s + 1, I_w = 1.1 / (2 (2.4 x 1.1 - 1)) = 0.3354 and I_rw = 1 / (2 (2.4 x 1.1 - 1)) =
// 0.3049 (for s^2 + sqrt(2) s + 1 both 1 / (2 sqrt(2))).
double pll_oscillator_jitter_rad(double bn_hz, int pll_order, double h0, double h_minus2);
// The PLL noise bandwidth long coherent integration uses at T = epochs x 20 ms (see ScalarTrackingOptions).
double long_coherent_pll_bw_hz(const ScalarTrackingOptions& options, int epochs);
// The number of 20 ms epochs (1, 2, 5, 10, 20) to integrate coherently at cn0_dbhz, with hysteresis around the
// current number (see ScalarTrackingOptions): the shortest whose jitter (thermal and the configured oscillator's)
// is within coherent_jitter_deg, else the one with the least jitter. oscillator_tracked: another loop takes the
// oscillator's phase noise (receiver/common_clock_loop.hpp), so thermal jitter alone decides.
int choose_coherent_epochs(const ScalarTrackingOptions& options, double cn0_dbhz, int current_epochs,
                           bool oscillator_tracked = false);

// The sums of one completed block: its length in epochs and seconds and the sign-corrected E, P, L taps.
struct CoherentBlockSums {
  int epochs = 0;
  double time_s = 0.0;
  std::complex<double> early{}, prompt{}, late{};
};

class LongCoherentIntegration final {
 public:
  explicit LongCoherentIntegration(const ScalarTrackingOptions& options) : opt_(options) {}

  // Long coherent integration is configured (max_coherent_ms > 20 on 20 ms coherent epochs).
  bool enabled() const { return opt_.max_coherent_ms > 20 && opt_.coherent_ms == 20; }
  // N chosen from the C/N0 (1: plain 20 ms updates).
  int target_epochs() const { return target_epochs_; }
  void set_target_epochs(int epochs) { target_epochs_ = epochs; }
  // The bits ahead a bit-synced channel's next update wants known (0: none wanted).
  int known_bits_wanted() const;
  // A C/N0 estimate (dB-Hz): low-passed over 1 s for the loss test; N re-chosen when bit_synced (on thermal
  // jitter alone when oscillator_tracked: choose_coherent_epochs).
  void add_cn0(double cn0_dbhz, bool bit_synced, bool oscillator_tracked = false);
  // The 1 s C/N0 is below threshold_dbhz (false before the first estimate).
  bool slow_cn0_below(double threshold_dbhz) const;
  // 20 ms updates bridging unknown bits between long updates of a weak bit-synced channel (at most 10 s after
  // the latest long update): their loss test reads the C/N0 as the long updates do.
  bool bridging(bool bit_synced, double time_s) const;
  // The PLI time constant of the loops' settings in effect (s).
  double pli_time_constant_s() const { return pli_tau_s_; }

  // The loops' settings for updates every `epochs` x 20 ms (1: the plain 20 ms loop): carrier loop bandwidth,
  // PLI time constant (the PLI restarts when the length changes), the carrier state re-referenced. bridging: as
  // bridging() at the call.
  void set_loop_epochs(int epochs, bool bridging, CarrierLoopFilter& carrier, PhaseLockIndicator& pli);
  // The carrier loop's frequency state re-referenced to updates of `epochs` x 20 ms.
  void rereference_carrier_state(int epochs, CarrierLoopFilter& carrier);
  // Back to 20 ms loops after the carrier loop and the PLI were restarted (re-lock): settings bookkeeping only.
  void restart_20ms_loops();

  // The block in progress: its epochs so far, its length (set at its first epoch), whether e continues it.
  int block_count() const { return block_count_; }
  int block_epochs() const { return block_epochs_; }
  bool continues_block(const CorrelationEpoch& e) const { return e.first_code_period == block_next_period_; }
  void drop_block() { block_count_ = 0; }
  // Starts a block of target_epochs() (block_count() == 0): true when its length differs from the carrier
  // state's reference, which is then re-referenced to it.
  bool start_block(CarrierLoopFilter& carrier);
  // Adds a 20 ms epoch with its known bit's sign (+1/-1); true when that completes the block.
  bool add(const CorrelationEpoch& e, int sign);
  // The completed block's sums; time_s: now (the latest long update, for bridging()).
  CoherentBlockSums finish_block(double time_s);

 private:
  ScalarTrackingOptions opt_;
  int target_epochs_ = 1;                        // chosen from the C/N0
  int loop_epochs_ = 1;                          // of the loops' settings in effect
  double loop_bw_hz_ = opt_.pll_bw_coherent_hz;  // the carrier loop's bandwidth set by set_loop_epochs
  bool oscillator_tracked_ = false;              // add_cn0's: another loop tracks the oscillator
  int state_epochs_ = 1;        // the update length (x 20 ms) the carrier loop's frequency state is referenced to
  double pli_tau_s_ = 0.0;      // PLI time constant set by set_loop_epochs (0: the option's)
  double cn0_slow_dbhz_ = 0.0;  // C/N0 estimates low-passed over 1 s
  bool have_slow_cn0_ = false;
  bool have_long_update_ = false;
  double last_long_update_s_ = 0.0;
  int block_epochs_ = 0, block_count_ = 0;
  std::int64_t block_next_period_ = 0;
  double block_time_s_ = 0.0;
  std::complex<double> block_early_{}, block_prompt_{}, block_late_{};
};

}  // namespace ultratrack::receiver

// Scalar tracking: the classic per-channel closure of the NcoCommand/CorrelationEpoch seam. Pull-in (a frequency
// search on the first prompts, or wide and narrow FLL stages; then a fine FLL) handing over to the Costas PLL
// (2nd/3rd order); carrier-aided DLL (normalised early-minus-late envelope);
// 1 ms epochs, then 20 ms coherent after bit sync; C/N0, phase-lock and C/N0 lock detectors; loss of lock is
// a state (kLost), never silently tracked noise. Units: Hz, chips, cycles, seconds; C/N0 in dB-Hz at the edge.
#pragma once

#include <array>
#include <complex>
#include <cstdint>
#include <optional>
#include <string>

#include "receiver/bit_sync.hpp"
#include "receiver/correlation_epoch.hpp"
#include "receiver/discriminators.hpp"
#include "receiver/lock_detectors.hpp"
#include "receiver/loop_filters.hpp"
#include "receiver/nco_command.hpp"
#include "receiver/presence_test.hpp"
#include "receiver/tracking_channel.hpp"

namespace ultratrack::receiver {

// All scalar-tracking settings, with defaults for L1 C/A in a static or vehicle receiver. Check with
// validation_error() at the edge (config file, command line) before constructing anything.
struct ScalarTrackingOptions {
  // Carrier loop
  int pll_order = 3;                   // 2 or 3
  double pll_bw_hz = 15.0;             // PLL noise bandwidth with 1 ms epochs; (0, 50]
  // On 1 ms epochs after phase lock while the measured C/N0 is below weak_cn0_dbhz: a narrower PLL (thermal
  // phase jitter sqrt(Bn / (C/N0) (1 + 1 / (2 T C/N0))): 14 deg at 15 Hz, 27 dB-Hz, against 9 deg at 6 Hz), for
  // the second or two before bit sync; a static or vehicle receiver's line-of-sight dynamics (< 1 g) stay within
  // a 3rd-order 6 Hz loop's reach.
  double pll_bw_weak_hz = 6.0;         // (0, 50]
  double weak_cn0_dbhz = 33.0;         // [0, 60]
  double pll_bw_coherent_hz = 5.0;     // with 20 ms epochs after bit sync; (0, 15]. Design (analogue) value: at
                                       // Bn*T = 0.1 the digital loop's true Bn is ~20 % higher, at 0.2 ~55 %
  // Pull-in: (1) a wide FLL alone on the two halves of each code period (range +-1 kHz, bit-edge safe); (2) a
  // narrow FLL alone on successive 1 ms prompts (bit-tolerant, range +-250 Hz, 8x less noise); (3) the PLL alone
  // (2nd order while pulling in) until the phase lock indicator holds, then the PLL of pll_order. Both FLLs are
  // first order and average cross and dot over ~4 epochs before the arctangent.
  // (0) When pullin_search_hz > 0 (default): instead of stages (1) and (2), a frequency search on the first
  // pullin_search_time_s of 1 ms prompts with the carrier held at the acquisition's frequency: the energy of
  // 10 ms coherent blocks, summed over blocks, at offsets +-pullin_search_hz (2.5 Hz grid, parabola through the
  // peak). Its noise is that of an estimate from 0.2 s of signal (a few Hz at 27 dB-Hz), where the FLL stages
  // wander +-20-130 Hz below ~32 dB-Hz (frequency jitter of a 1st-order FLL on 0.5-1 ms cross products): the
  // FLL stages suit a 1 ms acquisition on strong signals (pullin_search_hz = 0), the search any acquisition
  // whose Doppler is good to +-pullin_search_hz (refined 4-10 ms acquisitions: a few tens of Hz at worst).
  double pullin_search_hz = 300.0;     // [0, 500]; 0 = FLL stages (1), (2)
  double pullin_search_time_s = 0.2;   // [0.05, 0.5]
  double fll_bw_hz = 10.0;             // wide FLL; (0, 50]
  double fll_wide_time_s = 0.25;       // stage (1) length; [0.01, 5]
  double fll_narrow_bw_hz = 2.0;       // narrow FLL; (0, 20]
  double fll_narrow_time_s = 0.25;     // stage (2) length; [0, 5]
  // (2b) a fine FLL on successive 5 ms prompt sums (bit-tolerant, range +-50 Hz, 5x the SNR per measurement):
  // brings the frequency within the PLL's few-Hz lock-in range at low C/N0.
  double fll_fine_bw_hz = 2.0;         // fine FLL; (0, 10]
  double fll_fine_time_s = 0.3;        // stage (2b) length; [0, 5]
  double pullin_lock_time_s = 0.1;     // PLI above pli_lock_threshold this long ends pull-in; [0.01, 2]
  double pullin_timeout_s = 2.0;       // pull-in that never locks is declared lost; [0.1, 30] and longer than
                                       // the FLL stages plus pli_time_constant_s plus pullin_lock_time_s
  // Code loop
  double dll_bw_hz = 2.0;              // DLL noise bandwidth with 1 ms epochs; (0, 10]
  double dll_bw_coherent_hz = 1.0;     // after bit sync; (0, 5]
  double early_late_offset_chips = 0.5;  // E and L at +- this (E-L spacing twice it); (0, 0.5]; narrow: 0.1
  bool very_early_late = false;          // extra VE/VL taps in the epochs
  double very_early_late_offset_chips = 1.0;  // (early_late_offset_chips, 2]
  // Integration
  int coherent_ms = 20;                // coherent integration after bit sync, ms; 1, 2, 4, 5, 10 or 20
  BitSyncOptions bit_sync;
  // Lock detection
  Cn0Method cn0_method = Cn0Method::kNoiseTap;  // kMoments works without the noise tap (windows >= 50 epochs)
  double cn0_window_s = 0.2;           // C/N0 averaging window; [0.02, 5] (a multiple of the epoch length)
  double cn0_loss_threshold_dbhz = 25.0;  // C/N0 below this counts toward loss of lock; [0, 45]
  double pli_time_constant_s = 0.1;    // phase lock indicator low-pass; [0.005, 5]
  double pli_lock_threshold = 0.7;     // PLI (cos 2 dphi) above this = phase locked; (0, 1)
  double pli_loss_threshold = 0.3;     // PLI below this (after lock) counts toward loss; [-1, pli_lock_threshold)
  double loss_of_lock_time_s = 0.3;    // continuous time with a loss condition before kLost; [0.02, 10]
  // Coasting (allow_coasting): re-lock starts when the C/N0 estimate is this far above cn0_loss_threshold_dbhz;
  // a first-order FLL of relock_fll_bw_hz (cross/dot of each epoch's two halves: +-50 Hz at 20 ms) alone for
  // relock_fll_time_s, then the PLL assisted by that FLL at relock_assist_bw_hz until the PLI holds, with the
  // FLL's error below 1 / (4 T), for pullin_lock_time_s.
  double relock_margin_dbhz = 3.0;
  double relock_fll_bw_hz = 6.0;
  double relock_fll_time_s = 0.2;
  double relock_assist_bw_hz = 2.0;
  // Long coherent integration with data wipe-off (issue 7). After bit sync, while the navigation bits ahead are
  // known (receiver/nav_bit_predictor.hpp), N consecutive 20 ms epochs are summed with each bit's sign removed
  // (the channel's epochs stay 20 ms: one correlator, summed epochs) and the loops run once per N x 20 ms with
  // T = N x 20 ms: PLL and DLL noise bandwidths min(their 20 ms value, coherent_max_bn_t / T) (the loop
  // filters' gains follow T; at Bn T = 0.2 the digital loop is ~55 % wider than its design), the PLI on the long
  // sums (noise power N x the 20 ms one, time constant max(pli_time_constant_s, 10 T); the loss test waits as
  // long), and the C/N0 loss test at cn0_loss_threshold_dbhz - 10 log10 N (the pre-detection SNR of a 20 ms
  // epoch at the threshold) on the C/N0 estimates low-passed (in dB) over 1 s. Where bits are unknown the
  // channel stays on 20 ms (bits and C/N0 always come from 20 ms epochs: non-coherent across them).
  // N per channel from the measured C/N0 (adaptive_coherent): the shortest N in {1, 2, 5, 10, 20} (N x 20 <=
  // max_coherent_ms) whose thermal Costas PLL jitter sqrt(Bn / c (1 + 1 / (2 T c))) (c = C/N0 in Hz, Bn at that
  // T) is at most coherent_jitter_deg, else the longest; a shorter N only once it also holds coherent_hysteresis_db
  // lower. With the defaults (5 Hz at 20 ms, Bn T <= 0.2, 4 deg): 20 ms above 30.21 dB-Hz, 40 ms (still 5 Hz)
  // down to 30.16, 100 ms (2 Hz) below; with max_coherent_ms 200 or 400, 200 ms (1 Hz) below 26.18 and 400 ms
  // (0.5 Hz) below 23.17; back to a shorter time 2 dB above its threshold. A 1 Hz 3rd-order loop at 100 ms (Bn T
  // = 0.1) tracked a 0.5 Hz/s Doppler ramp with ~30 deg slow swings (its rate state's noise from the 5 Hz loop):
  // hence 0.2. adaptive_coherent = false: always max_coherent_ms while bits are known.
  int max_coherent_ms = 100;           // 20 (off), 40, 100, 200 or 400
  bool adaptive_coherent = true;
  double coherent_jitter_deg = 4.0;    // (0, 30]
  double coherent_hysteresis_db = 2.0; // [0, 10]
  double coherent_max_bn_t = 0.2;      // (0, 0.25]
  // Lock test of a channel whose replica a filter drives (ultra-tight: set_filter_driven): the scalar loss test
  // above (0.2 s C/N0 below cn0_loss_threshold_dbhz or PLI below pli_loss_threshold for loss_of_lock_time_s)
  // is replaced by receiver/presence_test.hpp on the 20 ms epochs: prompt power over the noise tap's over
  // non-overlapping presence_window_s windows, absent below presence_threshold_dbhz (one failing window: loss,
  // then coasting). With the defaults (1 s, 12 dB-Hz) a window misses an absent signal with probability 0.085
  // and calls a present one absent with 1.5e-3 at 18 dB-Hz, 7.5e-5 at 19, 1.0e-6 at 20 (exact: docs/validation.md):
  // a 60 s run is falsely lost with 8.7 % at 18, 0.45 % at 19, 0.006 % at 20 dB-Hz; an absent signal is declared
  // lost at the end of the first window without it with 91.5 % (1-2 s after it goes), one window later with 99.3 %.
  // Long coherent sums of such a channel use a pure (atan2) PLL discriminator: the bits are wiped.
  // Below ~22 dB-Hz one failing window no longer ends the lock: a loss needs k consecutive failing windows, k
  // the smallest up to presence_max_windows whose false-loss probability in a minute, exact at the channel's
  // level less 2 dB (the level: its latest windows reading >= presence_relock_dbhz), is at most
  // presence_false_loss_per_min (defaults: k = 1 for a level above 21.4 dB-Hz, as before; 2 down to 19.6, 3 to
  // 18.6, 4 to 17.8, then 5: a minute at 16 dB-Hz holds a false loss with probability 1.8e-5 (k = 5) instead of
  // 0.95, at 15 dB-Hz 1.9e-3, at 14 0.039; receiver/presence_test.hpp). A coasting
  // filter-driven channel re-locks when two consecutive windows read at least presence_relock_dbhz (noise does
  // so with probability 5.6e-5 per pair, a 16 dB-Hz signal with 0.48), as well as by the C/N0 rule above.
  double presence_window_s = 1.0;        // [0.1, 5]
  double presence_threshold_dbhz = 12.0; // [0, 30]
  int presence_max_windows = 5;          // [1, 10]
  double presence_false_loss_per_min = 1e-3;  // (0, 1)
  double presence_relock_dbhz = 15.0;    // [presence_threshold_dbhz, 40]
};

// Thermal phase jitter of a Costas PLL, radians: sqrt(Bn / c (1 + 1 / (2 T c))), c = 10^(cn0_dbhz / 10).
double pll_thermal_jitter_rad(double bn_hz, double t_s, double cn0_dbhz);
// The PLL noise bandwidth long coherent integration uses at T = epochs x 20 ms (see ScalarTrackingOptions).
double long_coherent_pll_bw_hz(const ScalarTrackingOptions& options, int epochs);
// The number of 20 ms epochs (1, 2, 5, 10, 20) to integrate coherently at cn0_dbhz, with hysteresis around the
// current number (see ScalarTrackingOptions).
int choose_coherent_epochs(const ScalarTrackingOptions& options, double cn0_dbhz, int current_epochs);

// Navigation bits known ahead of a 20 ms epoch (data wipe-off): the received sign (+1/-1, polarity applied) of
// the bit the epoch holds, and how many consecutive bits from it on are known (0: none, sign 0).
struct KnownBits {
  int sign = 0;
  int ahead = 0;
};

// Empty when the options are valid, else a message naming the first bad field, its value and its range.
std::string validation_error(const ScalarTrackingOptions& options);

// The channel configuration these options need (correlator layout with the noise tap when kNoiseTap).
ChannelConfig channel_config(const ScalarTrackingOptions& options, int prn, double sample_rate_hz, int num_antennas = 1);

enum class TrackingState {
  kPullIn,       // FLL stages, then the PLL until phase lock; 1 ms epochs
  kPhaseLocked,  // Costas PLL, 1 ms epochs, bit sync running
  kBitSynced,    // 20 ms (coherent_ms) epochs, bits flowing
  kLost,         // lock lost: the command only coasts; re-acquire
  // Lock lost while an external (vector) loop drives the replica: the carrier follows the loop's predicted
  // Doppler (aid_frequency), the code its commands; bits keep their timing; when the C/N0 returns a Costas PLL
  // with a frequency-error assist re-locks from the predicted frequency and the state goes back to kBitSynced.
  kCoasting,
};
const char* to_string(TrackingState state);

// What one loop update produced. The driver passes command (and set_coherent) to the channel.
struct TrackingReport {
  TrackingState state = TrackingState::kPullIn;
  NcoCommand command;
  bool set_coherent = false;  // ask the channel for coherent_periods-long epochs aligned to aligned_period
  int coherent_periods = 1;
  std::int64_t aligned_period = 0;
  std::optional<double> cn0_dbhz;  // latest estimate (none before the first window)
  double pli = 0.0;
  bool phase_locked = false;
  double phase_error_cycles = 0.0;   // discriminator outputs of this epoch
  double frequency_error_hz = 0.0;
  double code_error_chips = 0.0;
  std::optional<NavBit> bit;         // a completed 20 ms navigation bit
  // The integration time of the loops' latest update, ms: the epoch's length, or N x 20 ms with data wipe-off
  // (the loops then update once per N epochs and the other epochs give the previous command).
  int loop_integration_ms = 1;
};

class ScalarTracking final {
 public:
  // options must be valid (validation_error empty) or std::invalid_argument is thrown. initial: the command
  // the channel started with (from acquisition).
  ScalarTracking(const ScalarTrackingOptions& options, const NcoCommand& initial);

  TrackingReport update(const CorrelationEpoch& epoch, KnownBits known = {});
  // How many bits ahead long coherent integration wants to know before the next update (0: none wanted; the
  // caller then need not look them up).
  int known_bits_wanted() const;
  int coherent_epochs() const { return target_epochs_; }
  TrackingState state() const { return state_; }
  // External carrier aiding (vector tracking): shifts the carrier loop's frequency integrator, and the command it
  // gives next, by delta_hz (the predicted change of the Doppler since the previous aid), so that the PLL only
  // tracks what the prediction misses. Only while bit-synced; ignored otherwise.
  void aid_frequency(double delta_hz);
  // At the start of aiding: the loop's frequency-rate integrator (3rd order) holds the line-of-sight dynamics it
  // learnt alone; the aiding brings them from now on, so the integrator is cleared (else they count twice).
  void start_aiding();
  // Coasting (vector tracking): while allowed, a loss of lock in kBitSynced enters kCoasting instead of kLost.
  // Disallowing it while coasting declares the channel lost.
  void allow_coasting(bool allowed);
  bool coasting() const { return state_ == TrackingState::kCoasting; }
  // Filter-driven (ultra-tight): while set and bit-synced, lock is judged by the presence test alone and long
  // coherent sums use a pure PLL (see ScalarTrackingOptions::presence_window_s). Off: the scalar loss test.
  void set_filter_driven(bool driven);
  bool filter_driven() const { return filter_driven_; }
  // Vector FLL (VectorChannelCommand::carrier_commanded): while set and bit-synced or coasting, the carrier NCO's
  // frequency is the external loop's (command_carrier), the channel's carrier loop does not run, long coherent
  // integration is off, bits are detected differentially (BitAssembler::set_differential: the replica's phase
  // wanders by the frequency error's integral), the loss test is the C/N0 alone (the PLI reads the wandering
  // phase; filter-driven, as the vector FLL's channels are: the presence test), and coasting ends as soon as the
  // C/N0 is back or the presence test finds the signal (nothing to re-lock). Clearing it hands the carrier
  // back to the PLL from the commanded frequency (its frequency-rate state cleared, the PLI restarted).
  // phase_locked (vector PLL, VectorChannelCommand::carrier_phase_locked): the external loop closes the phase too,
  // so the bits are detected coherently (Costas sign, polarity from the preamble) rather than differentially;
  // everything else as the FLL. Changing it alone switches the bit detection.
  void set_carrier_commanded(bool commanded, bool phase_locked = false);
  bool carrier_commanded() const { return carrier_commanded_; }
  bool carrier_phase_locked() const { return carrier_commanded_ && carrier_phase_locked_; }
  // The commanded carrier frequency (Hz), for the next command; ignored unless carrier_commanded() and bit-synced
  // or coasting.
  void command_carrier(double frequency_hz);
  // The C/N0 of the latest completed presence window (dB-Hz; -100 before the first or without signal).
  double presence_cn0_dbhz() const { return presence_.last_cn0_dbhz(); }
  // The absent windows a filter-driven channel's loss needs at its current level (PresenceMonitor).
  int presence_required_windows() const { return presence_.required_windows(); }
  bool relocking() const { return relocking_; }
  std::optional<double> cn0_dbhz() const { return cn0_dbhz_; }
  double pli() const { return pli_.value(); }
  // Bit sync result (valid once state is kBitSynced or bit_synchronised()).
  bool bit_synchronised() const { return bit_sync_.synchronised(); }
  std::int64_t bit_edge_period() const { return bit_sync_.edge_period(); }

 private:
  double fine_fll(std::complex<float> prompt, double t_s, double* frequency_error_hz);
  double search_frequency_offset_hz() const;
  TrackingReport coast_epoch(const CorrelationEpoch& e, TrackingReport& r, bool add_bit);
  void relock_from_presence();
  TrackingReport lose_long_coherent_lock(const CorrelationEpoch& e, TrackingReport& r, bool add_bit);
  TrackingReport long_coherent_epoch(const CorrelationEpoch& e, TrackingReport& r, int sign);
  void set_loop_epochs(int epochs);
  void rereference_carrier_state(int epochs);
  bool slow_cn0_below(double threshold_dbhz) const;
  bool bridging() const;
  bool long_enabled() const { return opt_.max_coherent_ms > 20 && opt_.coherent_ms == 20; }

  static constexpr int kMaxSearchEpochs = 500;

  ScalarTrackingOptions opt_;
  TrackingState state_ = TrackingState::kPullIn;
  CarrierLoopFilter carrier_;
  NcoCommand command_;
  PhaseLockIndicator pli_;
  Cn0Estimator cn0_;
  int cn0_epoch_periods_ = 1;
  std::optional<double> cn0_dbhz_;
  double noise_power_ = 0.0;  // low-passed |noise tap|^2 for the current epoch length
  int noise_epoch_periods_ = 1;
  BitSynchronizer bit_sync_;
  std::optional<BitAssembler> bits_;
  bool coherent_requested_ = false;
  double time_s_ = 0.0, locked_time_s_ = 0.0, loss_time_s_ = 0.0;
  bool ever_locked_ = false;
  bool coasting_allowed_ = false, relocking_ = false;
  bool filter_driven_ = false;
  bool carrier_commanded_ = false;
  bool carrier_phase_locked_ = false;
  PresenceMonitor presence_;
  bool presence_absent_ = false;  // the latest completed presence window ended a run of absent ones: lost
  bool presence_found_ = false;   // ... ended a run of present ones (re-lock while coasting)
  CrossDot relock_fll_{};
  double relock_s_ = 0.0;
  std::complex<float> previous_prompt_{};
  CrossDot fll_average_{};
  std::complex<double> fine_sum_{}, fine_previous_{};
  int fine_count_ = 0;
  double fine_time_s_ = 0.0;
  bool fine_have_previous_ = false;
  bool wide_fll_ = true;
  // pull-in stage ends (s since the channel's start)
  double search_end_s_ = 0.0, wide_end_s_ = 0.0, narrow_end_s_ = 0.0, pll_start_s_ = 0.0;
  std::array<std::complex<float>, kMaxSearchEpochs> search_prompts_{};
  int search_count_ = 0;
  double initial_frequency_hz_ = 0.0;
  double pll_bw_now_hz_ = 0.0;
  double smoothed_frequency_hz_ = 0.0;  // NCO frequency and rate low-passed while phase-locked at 1 ms
  bool smoothing_started_ = false;
  double previous_t_s_ = 0.0;
  // long coherent integration
  int target_epochs_ = 1;   // chosen from the C/N0
  int loop_epochs_ = 1;     // of the loops' settings in effect
  int state_epochs_ = 1;    // the update length (x 20 ms) the carrier loop's frequency state is referenced to
  double pli_tau_s_ = 0.0;  // PLI time constant set by set_loop_epochs (0: the option's)
  double cn0_slow_dbhz_ = 0.0;  // C/N0 estimates low-passed over 1 s
  bool have_slow_cn0_ = false;
  bool have_long_update_ = false;
  double last_long_update_s_ = 0.0;
  int block_epochs_ = 0, block_count_ = 0;
  std::int64_t block_next_period_ = 0;
  double block_time_s_ = 0.0;
  std::complex<double> block_early_{}, block_prompt_{}, block_late_{};
};

// Runs a channel under a scalar closure over one block: feeds samples, updates the loop at every epoch, passes
// commands back, and calls on_epoch(const CorrelationEpoch&, const TrackingReport&) for each epoch.
template <class OnEpoch>
void track_block(TrackingChannel& channel, ScalarTracking& loop, const SampleBlockView& block, OnEpoch&& on_epoch) {
  int offset = 0;
  while (offset < block.num_samples) {
    const auto r = channel.feed(block, offset);
    offset += r.consumed;
    if (!r.epoch_ready) continue;
    const TrackingReport report = loop.update(channel.epoch());
    channel.command(report.command);
    if (report.set_coherent) channel.set_coherent_periods(report.coherent_periods, report.aligned_period);
    on_epoch(channel.epoch(), report);
  }
}

}  // namespace ultratrack::receiver

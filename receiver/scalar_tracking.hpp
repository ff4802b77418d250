// SPDX-License-Identifier: GPL-3.0-or-later
// Scalar tracking: the classic per-channel closure of the NcoCommand/CorrelationEpoch seam. Pull-in (a frequency
// search on the first prompts, or wide and narrow FLL stages; then a fine FLL) handing over to the Costas PLL
// (2nd/3rd order); carrier-aided DLL (normalised early-minus-late envelope);
// 1 ms epochs, then 20 ms coherent after bit sync; C/N0, phase-lock and C/N0 lock detectors; loss of lock is
// a state (kLost), never silently tracked noise. Units: Hz, chips, cycles, seconds; C/N0 in dB-Hz at the edge.
// The class composes its stages: PullIn (pull_in.hpp), LongCoherentIntegration (long_coherent.hpp),
// LossOfLockTest (loss_of_lock.hpp) and FadeDetector (fade_detector.hpp: a blockage seen within an epoch, so that
// the channel's measurements stop before the loss test ends its lock); its options are in scalar_tracking_options.hpp.
#pragma once

#include <cmath>
#include <cstdint>
#include <optional>

#include "receiver/bit_sync.hpp"
#include "receiver/carrier_control.hpp"
#include "receiver/correlation_epoch.hpp"
#include "receiver/discriminators.hpp"
#include "receiver/fade_detector.hpp"
#include "receiver/lock_detectors.hpp"
#include "receiver/long_coherent.hpp"
#include "receiver/loop_filters.hpp"
#include "receiver/loss_of_lock.hpp"
#include "receiver/nco_command.hpp"
#include "receiver/pull_in.hpp"
#include "receiver/scalar_tracking_options.hpp"
#include "receiver/tracking_channel.hpp"

namespace ultratrack::receiver {

// Navigation bits known ahead of a 20 ms epoch (data wipe-off): the received sign (+1/-1, polarity applied) of
// the bit the epoch holds, and how many consecutive bits from it on are known (0: none, sign 0).
struct KnownBits {
  int sign = 0;
  int ahead = 0;
};

enum class TrackingState {
  kPullIn,       // FLL stages, then the PLL until phase lock; 1 ms epochs
  kPhaseLocked,  // Costas PLL, 1 ms epochs, bit sync running
  kBitSynced,    // 20 ms (coherent_ms) epochs, bits flowing
  kLost,         // lock lost: the command only coasts; re-acquire
  // Lock lost while an external (vector) loop drives the replica: the carrier follows the loop's predicted
  // Doppler (ScalarTrackingControl::aid), the code its commands; bits keep their timing; when the C/N0 returns a Costas
  // PLL with a frequency-error assist re-locks from the predicted frequency and the state goes back to kBitSynced.
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
  double phase_error_cycles = 0.0;  // discriminator outputs of this epoch
  double frequency_error_hz = 0.0;
  double code_error_chips = 0.0;
  std::optional<NavBit> bit;  // a completed 20 ms navigation bit
  // The integration time of the loops' latest update, ms: the epoch's length, or N x 20 ms with data wipe-off
  // (the loops then update once per N epochs and the other epochs give the previous command).
  int loop_integration_ms = 1;
};

// How carrier aiding moves the carrier loop (ScalarTrackingControl::aid).
enum class CarrierAid {
  kNone,
  // At the start of aiding: the loop's frequency-rate integrator (3rd order) holds the line-of-sight dynamics it
  // learnt alone; the aiding brings them from now on, so the integrator is cleared (else they count twice).
  kStart,
  // Shifts the carrier loop's frequency integrator, and the command it gives next, by aid_delta_hz (the
  // predicted change of the Doppler since the previous aid), so that the PLL only tracks what the prediction
  // misses.
  kShift,
};

// What an external (vector) loop sets on a scalar channel, applied in one call (ScalarTracking::apply). The
// defaults are a channel with no external loop.
struct ScalarTrackingControl {
  // Coasting: while allowed, a loss of lock in kBitSynced enters kCoasting instead of kLost. Disallowing it
  // while coasting declares the channel lost.
  bool coasting_allowed = false;
  // Filter-driven (ultra-tight): while set and bit-synced, lock is judged by the presence test alone and long
  // coherent sums use a pure PLL (see ScalarTrackingOptions::presence_window_s). Off: the scalar loss test.
  bool filter_driven = false;
  // kFrequency (vector FLL): while bit-synced or coasting, the carrier NCO's frequency is the external loop's
  // (carrier_frequency_hz), the channel's carrier loop does not run, long coherent integration is off, bits are
  // detected differentially (BitAssembler::set_differential: the replica's phase wanders by the frequency error's
  // integral), the loss test is the C/N0 alone (the PLI reads the wandering phase; filter-driven, as the vector
  // FLL's channels are: the presence test), and coasting ends as soon as the C/N0 is back or the presence test finds
  // the signal (nothing to re-lock). Back to kAided hands the carrier to the PLL from the commanded frequency (its
  // frequency-rate state cleared, the PLI restarted).
  // kFrequencyAndPhase (vector PLL): the external loop closes the phase too, so the bits are detected coherently
  // (Costas sign, polarity from the preamble) rather than differentially; everything else as kFrequency.
  CarrierControl carrier = CarrierControl::kAided;
  // The commanded carrier frequency (Hz) for the next command, with kFrequency or kFrequencyAndPhase; ignored unless
  // bit-synced or coasting, or when not finite.
  double carrier_frequency_hz = NAN;
  // Carrier aiding (vector tracking, with kAided): only while bit-synced (kShift: or coasting);
  // ignored otherwise. aid_delta_hz (kShift) not finite: ignored.
  CarrierAid aid = CarrierAid::kNone;
  double aid_delta_hz = 0.0;
  // The external loop also tracks the receiver oscillator for this channel (receiver/common_clock_loop.hpp: its
  // frequency reaches the NCO through the aid): the PLL sees the oscillator's residual only, so long coherent
  // integration chooses its length on thermal jitter (choose_coherent_epochs without the oscillator). With
  // filter_driven, the PLL also holds on the aiding through the first tenths of a second of a sudden fade (below).
  bool clock_steered = false;
};

class ScalarTracking final {
 public:
  // options must be valid (IsValid) or std::invalid_argument is thrown. initial: the command
  // the channel started with (from acquisition).
  ScalarTracking(const ScalarTrackingOptions& options, const NcoCommand& initial);

  TrackingReport update(const CorrelationEpoch& epoch, KnownBits known = {});
  // How many bits ahead long coherent integration wants to know before the next update (0: none wanted; the
  // caller then need not look them up).
  int known_bits_wanted() const;
  int coherent_epochs() const { return long_.target_epochs(); }
  TrackingState state() const { return state_; }
  // The external loop's control (see ScalarTrackingControl), in this order: coasting, filter-driven, commanded
  // carrier, then the commanded frequency or the aid.
  void apply(const ScalarTrackingControl& control);
  // The standing part of the control in effect (aid kNone, carrier_frequency_hz NaN).
  ScalarTrackingControl control() const;
  bool coasting() const { return state_ == TrackingState::kCoasting; }
  bool filter_driven() const { return filter_driven_; }
  bool carrier_commanded() const { return carrier_commanded_; }
  bool carrier_phase_locked() const { return carrier_commanded_ && carrier_phase_locked_; }
  // The C/N0 of the latest completed presence window (dB-Hz; -100 before the first or without signal).
  double presence_cn0_dbhz() const { return loss_.presence_cn0_dbhz(); }
  // The absent windows a filter-driven channel's loss needs at its current level (PresenceMonitor).
  int presence_required_windows() const { return loss_.presence_required_windows(); }
  bool relocking() const { return relocking_; }
  // A sudden fade of a strong signal (receiver/fade_detector.hpp: a blockage) is in progress: the loops run on, but
  // what they measure is noise-driven until it ends.
  bool signal_faded() const { return fade_.faded(); }
  long long signal_fades() const { return fade_.fades(); }
  std::optional<double> cn0_dbhz() const { return cn0_dbhz_; }
  double pli() const { return pli_.value(); }
  // Bit sync result (valid once state is kBitSynced or bit_synchronised()).
  bool bit_synchronised() const { return bit_sync_.synchronised(); }
  std::int64_t bit_edge_period() const { return bit_sync_.edge_period(); }

 private:
  void allow_coasting(bool allowed);
  void set_filter_driven(bool driven);
  void set_carrier_commanded(bool commanded, bool phase_locked);
  void command_carrier(double frequency_hz);
  void aid_frequency(double delta_hz);
  void start_aiding();
  TrackingReport coast_epoch(const CorrelationEpoch& e, TrackingReport& r, bool add_bit);
  void relock_from_presence();
  TrackingReport lose_long_coherent_lock(const CorrelationEpoch& e, TrackingReport& r, bool add_bit);
  TrackingReport long_coherent_epoch(const CorrelationEpoch& e, TrackingReport& r, int sign);
  void set_loop_epochs(int epochs);
  bool bridging() const;

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
  double time_s_ = 0.0, locked_time_s_ = 0.0;
  bool ever_locked_ = false;
  bool coasting_allowed_ = false, relocking_ = false;
  bool filter_driven_ = false;
  bool clock_steered_ = false;  // ScalarTrackingControl::clock_steered
  // A filter-driven channel whose oscillator an external loop steers holds its PLL while the fade detector says its
  // prompt fell 10 dB in one epoch and the C/N0 estimate (0.2 s) still reads the signal of before (30 dB-Hz or
  // more): the carrier then moves by the aiding alone (the filter's Doppler and the common clock loop). At a step
  // from 45 to 20 dB-Hz the PLL otherwise ran on noise with the strong signal's bandwidth and coherent time until
  // the estimate followed (0.2-0.3 s), and left single channels 2-5 Hz off (campaigns/weak_signal_told_tuning.toml:
  // 6 of 8 satellites lost within 1 s of the step). Once the estimate reads the new level the loop runs again, on
  // the weak signal's settings, fade or not: at 20 dB-Hz the fade's own end (a presence test at 20 dB-Hz) may take
  // seconds, and a PLL held that long drifted with the aiding (5 of 10 channels 2-4 Hz off on one file).
  bool aided_hold() const {
    constexpr double kHoldWhileAboveDbHz = 30.0;
    return filter_driven_ && clock_steered_ && state_ == TrackingState::kBitSynced && fade_.faded() && cn0_dbhz_ &&
           *cn0_dbhz_ >= kHoldWhileAboveDbHz;
  }
  bool carrier_commanded_ = false;
  bool carrier_phase_locked_ = false;
  PullIn pull_in_;
  LongCoherentIntegration long_;
  LossOfLockTest loss_;
  FadeDetector fade_;
  CrossDot relock_fll_{};
  double relock_s_ = 0.0;
  double pll_bw_now_hz_ = 0.0;
  double smoothed_frequency_hz_ = 0.0;  // NCO frequency and rate low-passed while phase-locked at 1 ms
  bool smoothing_started_ = false;
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

// SPDX-License-Identifier: GPL-3.0-or-later
// Ultra-tight coupling (`receive --imu F --coupling ultra-tight --filter ekf|ukf [--ut-measurement iq|discriminator]`):
// the closed-loop ultra-tight driver (fusion/ultratight_integration.hpp) attached to the receiver engine through the
// vector-loop seam (receiver/vector_loop.hpp). Channels acquire and pull in as scalar while the tight integration
// of pipelines/gnss_ins_coupler.hpp aligns and runs; then the driver starts from the tight filter's state and, every
// 20 ms, (1) runs the INS to the vector epoch, (2) updates from each synchronised channel's latest correlation
// epoch (E/P/L I&Q normalised to unit noise, data bit removed by the prompt's sign, the replica that actually ran
// given explicitly), (3) predicts every satellite's replica and commands each channel's code (rate and phase jump)
// and carrier aiding (predicted Doppler, plus the common clock loop's frequency: receiver/common_clock_loop.hpp, which
// tracks the receiver oscillator on all channels' prompts at once; the channel's Costas PLL stays closed, so carrier
// phase stays continuous).
// A channel that loses lock coasts on the prediction and re-locks without acquisition. A weak channel whose PLL
// runs away from the predicted Doppler (fusion/false_lock_monitor.hpp) is left out of the filter, stepped back onto the
// prediction and its carrier phase flagged as slipped; one that keeps running away is released. A channel whose
// windowed NIS is far outside its band (fusion/nis_release.hpp: its correlations contradict the prediction) is
// released to its scalar loops and left out of the filter until it loses synchronisation; the channels' pooled
// windows outside their band re-open the filter's covariance instead. Every release is logged (summary.json). Every
// vector epoch after the hand-over goes to the sink (UltraTightEpochLog: ultratight.csv), the navigation rows through
// the coupler's sink (nav.csv). With --odometer the driver carries the odometer states (fusion::UltraTightOptions::
// odometer) and takes the windows the tight integration left at their times, IMU rows split there. Time: the driver's
// t_s is IMU time (GPS time minus the IMU time origin); its clock bias is against the receiver clock with the engine's
// clock jumps since the hand-over taken out. Units: s, m, m/s, Hz, chips.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <optional>
#include <span>
#include <string>

#include "fusion/false_lock_monitor.hpp"
#include "fusion/nis_release.hpp"
#include "fusion/ultratight_integration.hpp"
#include "pipelines/gnss_ins_coupler.hpp"
#include "pipelines/prompt_power_average.hpp"
#include "pipelines/receive_sinks.hpp"
#include "receiver/common_clock_loop.hpp"
#include "receiver/receiver_engine.hpp"
#include "receiver/vector_loop.hpp"

namespace ultratrack::pipelines {

struct UltraTightLoopOptions {
  double period_s = 0.020;        // vector epoch = the driver's period = the channels' 20 ms coherent epochs
  double handover_after_s = 2.0;  // the tight integration runs this long (IMU time) before the hand-over
  double max_jump_chips = 0.5;    // a channel joins / stays only while prediction and replica agree this well
  double max_coast_s = 30.0;      // a coasting channel is released (scalar, then lost) after this
  // Satellites above this elevation are commanded by the loop (INS-predicted replicas); only those above the
  // PVT's mask update the filter (fusion::UltraTightOptions::measurement_mask_rad). Between the two masks a
  // channel is "aided only": its replica follows the prediction, its correlations are not used.
  double command_mask_deg = 5.0;
  // Carrier runaway (a weak channel's aided PLL off its signal: fusion::FalseLockMonitor). Below runaway_below_dbhz
  // (the channel's C/N0 estimate) the 1 s mean of replica carrier minus the filter's predicted Doppler is checked;
  // above runaway_hz the channel's correlations are left out of the filter until a later 1 s mean is within it,
  // its aiding steps once by minus that mean (its PLL back onto the prediction), and its carrier phase is reported
  // with loss of lock. 5 Hz: above every 1 s mean of locked channels at 16-18 dB-Hz, below every runaway one
  // (docs/validation.md). Strong channels are left alone: there the PLL follows the signal and the prediction, not
  // the PLL, is what lags (10 g turn).
  double runaway_below_dbhz = 30.0;
  double runaway_average_s = 1.0;
  double runaway_hz = 5.0;
  // The same test on the offset from the channels' common one (the median over at least 4 commanded channels: the
  // filter's clock error, which every replica shares and the common clock loop has taken out of them but not out
  // of the prediction). 1 Hz, from benchmarks/validation/runaway_offsets.py on campaigns/weak_signal_told_more.toml
  // (TCXO, 20-22 dB-Hz, 2 Hz then): the channels the simulator's truth keeps have their 1 s mean within 0.51 Hz of the
  // median in 99 % of 12,980 channel-seconds (26 beyond 1 Hz), while 15 of the 18 satellites lost there had a 1 s mean
  // beyond 1 Hz before the truth's rule (2.5 Hz over 1 s) called them lost, and 2 beyond 2 Hz: a PLL unlocked by the
  // step to 20 dB-Hz wanders off slowly, and at 2 Hz its re-centring came too late.
  double runaway_relative_hz = 1.0;
  // A channel still beyond runaway_hz in the 1 s after each of this many re-centrings in a row is not locked (its
  // PLL cannot hold the signal): the loop releases it (scalar, then lost) instead of keeping it "bit-synced".
  int runaway_max_recentres = 3;
  // Windowed NIS per channel and for the whole filter (fusion/nis_release.hpp). A filter event re-opens the
  // covariance (fusion::inflate_for_recovery): position and clock bias 1-sigma at least reopen_position_sigma_m,
  // velocity and clock drift at least reopen_velocity_sigma_mps (well inside the I&Q model's pull-in: +-1 chip of
  // code, +-25 Hz of carrier at 20 ms), attitude at fusion::LockoutRecoveryOptions' defaults.
  fusion::NisReleaseOptions nis;
  // A channel's window restarts when it coasts and takes no update until this long after its re-lock: in the first
  // second after a re-lock the PLL's residual phase makes the gate refuse a third of its updates at 45 dB-Hz (a
  // transient of the model, not a wrong prediction: docs/validation.md), which alone filled a window to 4.4 x its dof.
  double nis_settle_s = 1.0;
  double reopen_position_sigma_m = 15.0;
  double reopen_velocity_sigma_mps = 1.0;
  // Carrier-phase rates (fusion/carrier_rate_measurement.hpp): every this many seconds each contiguously tracked
  // channel's replica phase change over the window since its previous one updates the filter's range rates (and so
  // the common clock drift, which a TCXO moves by ~1 Hz / sqrt(s): docs/validation.md). 0: off.
  double carrier_rate_window_s = 0.2;
  // The common clock loop (receiver/common_clock_loop.hpp): the receiver oscillator's phase tracked once on all the
  // commanded channels' prompts (noise bandwidth, Hz) and added to every one's carrier aid, so that each PLL integrates
  // on thermal jitter alone. 0: off (each PLL follows the oscillator itself).
  double common_clock_bw_hz = 5.0;
};

class UltraTightLoop final : public receiver::VectorLoop {
 public:
  // fusion: the tight pull-in (options().coupling kUltraTight); sink: every epoch after the hand-over. Both must
  // outlive this.
  UltraTightLoop(GnssInsCoupler& fusion, ReceiveSink& sink, UltraTightLoopOptions ut = {});
  void attach(receiver::ReceiverEngine& engine);
  void update(const receiver::VectorEpochInput& epoch, std::span<receiver::VectorChannelCommand> commands) override;
  // Runs the INS to end_sample (the receiver's next unprocessed sample).
  void finish(std::int64_t end_sample);

  bool handed_over() const { return driver_.has_value(); }
  long long channel_epochs() const { return channel_epochs_; }  // channel-epochs commanded by the loop
  const fusion::UltraTightIntegration* driver() const { return driver_ ? &*driver_ : nullptr; }
  const fusion::ReleaseLog& release_log() const { return release_log_; }
  std::string summary_json() const;  // the "ultratight" member of summary.json
  std::string report() const;        // one line for stdout

 private:
  struct ChannelState {
    bool commanded = false;  // in vector mode under this loop (as of the last command)
    double coast_s = 0.0;
    bool ever = false;
    bool was_coasting = false;
    double since_relock_s = 1e9;      // time since the channel last stopped coasting (NIS settling)
    PromptPowerAverage prompt_power;  // the I&Q model's amplitude
    double aid_hz = NAN;              // the carrier aiding sent (changes by the INS propagation only)
    // The command sent last (vector): a pipelined loop's is still pending when the next inputs are taken.
    double sent_code_rate_chips_per_s = 0.0, sent_jump_chips = 0.0;
    // Carrier runaway (UltraTightLoopOptions::runaway_hz): the monitor, whether the channel is judged off its
    // signal now (left out of the filter, its phase flagged), and the aiding step still to send (Hz).
    fusion::FalseLockMonitor runaway;  // kBlock over UltraTightLoopOptions::runaway_average_s
    bool runaway_off = false;
    double pending_step_hz = 0.0;
    int runaway_repeats = 0;        // re-centrings in a row each followed by a 1 s mean still beyond runaway_hz
    bool runaway_given_up = false;  // released for that; commanded again only after a new synchronisation
    bool nis_released = false;      // released by its windowed NIS: scalar and out of the filter until then too
    std::string nis_detail;         // the release's reason
    double last_offset_hz = NAN;    // the latest epoch's replica minus predicted Doppler (ultratight.csv)
    // The carrier-phase rate window (ChannelCorrelation::has_carrier_rate): its start (IMU time of an epoch's middle,
    // the replica's phase there, that phase's jitter variance) and the latest epoch that continued it.
    bool rate_anchored = false;
    double rate_t0_s = 0.0, rate_phase0_cycles = 0.0, rate_var0_rad2 = 0.0, rate_last_t_s = 0.0;
  };
  ChannelState& channel(int prn);  // made on first use
  void start(const receiver::VectorEpochInput& epoch, double t_k);
  double imu_time(const receiver::VectorEpochInput& epoch, std::int64_t sample) const;
  void feed_imu_to(double t);
  void emit_nav();
  std::vector<fusion::ChannelCorrelation> correlations(const receiver::VectorEpochInput& epoch, double t_k);
  std::map<int, double> propagated_doppler_change();
  double predicted_doppler_at(int prn, double t_s) const;
  bool runaway_check(const receiver::VectorChannelInput& in, double t_mid_s, double common_offset_hz);
  // The median of the commanded channels' carrier offsets (replica minus predicted Doppler) at this epoch; NaN with
  // fewer than 4.
  double common_carrier_offset_hz(const receiver::VectorEpochInput& epoch, double t_k) const;
  void carrier_rate(const receiver::VectorChannelInput& in, double t_mid_s, double phase_var_rad2, ChannelState& st,
                    fusion::ChannelCorrelation& c) const;
  void command(const receiver::VectorEpochInput& epoch, double t_k, std::span<receiver::VectorChannelCommand> out,
               const std::map<int, double>& aid_change, double clock_change_hz = 0.0);
  // The common clock loop's update from the commanded channels' latest prompts: the change of its frequency (Hz).
  double common_clock_update(const receiver::VectorEpochInput& epoch);
  // The windowed NIS tests after a period's updates (t_s: receiver time for the log).
  void nis_tests(double t_s);

  GnssInsCoupler& fusion_;
  ReceiveSink& sink_;
  receiver::ReceiverOptions options_;
  UltraTightLoopOptions ut_;
  UltraTightEpochLog log_;  // the epoch being logged (its channel vector reused)
  std::optional<fusion::UltraTightIntegration> driver_;
  std::vector<signals::Ephemeris> ephemerides_;  // the driver's: one per PRN at the hand-over, then every later one
  std::size_t ephemerides_seen_ = 0;             // VectorEpochInput::ephemerides entries already considered
  signals::GpsTime origin_;
  double corrections_at_start_s_ = 0.0;  // the engine's clock corrections at the hand-over
  double t_ins_ = 0.0;                   // the driver's INS time (IMU rows split at vector epochs)
  std::size_t next_imu_ = 0;
  bool period_open_ = false;
  std::map<int, fusion::ReplicaCommand> period_replicas_;    // the open period's replicas by PRN
  std::map<int, fusion::ReplicaCommand> previous_replicas_;  // the period's before it (predicted Doppler's slope)
  std::map<int, ChannelState> channels_;
  std::optional<double> first_integration_t_s_;
  std::optional<std::int64_t> last_sample_;
  double last_t_s_ = 0.0;
  // Counts.
  double handover_t_s_ = 0.0;
  std::int64_t handover_sample_ = 0;
  long long vector_epochs_ = 0, channel_epochs_ = 0, coasting_channel_epochs_ = 0, releases_ = 0, relocks_ = 0;
  long long measurements_ = 0, known_bits_ = 0, not_wiped_ = 0;
  long long runaway_recentres_ = 0, runaway_left_out_ = 0, runaway_releases_ = 0;
  fusion::NisReleaseMonitor nis_;
  std::optional<receiver::CommonClockLoop> clock_loop_;  // UltraTightLoopOptions::common_clock_bw_hz > 0
  fusion::ReleaseLog release_log_;
  long long filter_reopens_ = 0;
  // Odometer aiding (--odometer): the windows the tight integration left, the next to hand to the driver, how many
  // it took, and the last time the driver's satellite updates were accepted (the odometer object's GNSS end).
  std::vector<fusion::OdometerSpeed> odometer_;
  std::size_t next_odometer_ = 0;
  long long odometer_windows_ = 0;
  long long accepted_before_ = 0;
  double gnss_last_used_s_ = 0.0;
  void record_odometer();
};

}  // namespace ultratrack::pipelines

// SPDX-License-Identifier: GPL-3.0-or-later
// Tracking channel: one satellite's replica (code and carrier NCOs in fixed point) plus the correlator engine and
// the epoch boundary logic. Epochs start where the replica code crosses a code-period start and span 1 period
// (1 ms), or N periods aligned to a given period (20 ms after bit sync). The channel never decides where its
// replica goes: it applies the NcoCommand given by whichever loop is closed (scalar, vector, ultra-tight) at the
// start of its next epoch. Several antennas on one clock are correlated against the one replica.
#pragma once

#include <array>
#include <complex>
#include <cstdint>
#include <optional>

#include "receiver/correlation_epoch.hpp"
#include "receiver/correlator_engine.hpp"
#include "receiver/nco.hpp"
#include "receiver/nco_command.hpp"

namespace ultratrack::receiver {

// Which correlators the channel runs. Offsets are from prompt in chips; early taps lead, late taps lag.
struct CorrelatorLayout {
  double early_late_offset_chips = 0.5;       // E and L at +-this; (0, 1]. 0.5 = 1 chip E-L spacing; narrow: 0.1
  bool very_early_late = false;               // VE/VL taps (multipath monitoring, BOC-style discriminators)
  double very_early_late_offset_chips = 1.0;  // (early_late_offset_chips, 2]
  bool noise = true;                          // off-peak noise tap (noise_tap_offset_chips), for C/N0 and lock tests
  // Antennas 1.. (slaves) get only the prompt and the noise tap (what the between-antenna phase and its C/N0 need),
  // from a second engine over the same replica; their other taps read zero. false: every antenna every tap.
  bool slaves_prompt_and_noise_only = true;
};

struct ChannelConfig {
  int prn = 1;                  // 1..32
  double sample_rate_hz = 4e6;  // complex baseband sample rate, Hz; > 1.1 MHz (the code must fit Nyquist)
  int num_antennas = 1;         // 1..kMaxAntennas, sampled on one clock; antenna 0 is the master
  CorrelatorLayout layout;
};

// Where the replica starts, e.g. from acquisition: the code phase holds at sample_index. code_phase_chips is the
// position within the code at that sample (chip index plus fraction: 0 = the first chip of a period is just
// starting), so the next period starts (1023 - code_phase_chips) / rate seconds later. An acquisition that reports
// the delay to the next code start instead converts with code_phase_chips = 1023 - delay_chips.
struct ChannelStart {
  std::int64_t sample_index = 0;      // receiver sample index at which code_phase_chips holds
  double code_phase_chips = 0.0;      // [0, 1023): replica code phase at that sample
  double carrier_frequency_hz = 0.0;  // Doppler at baseband, Hz
  double carrier_phase_cycles = 0.0;
  // Code rate, chips/s; 0 means derived from the carrier (1.023e6 * (1 + f / f_L1), carrier-aided).
  double code_rate_chips_per_s = 0.0;
};

// A start from an acquisition that reports where the next code period begins: samples_to_code_start samples
// (fractional) after first_sample, with carrier Doppler doppler_hz, at sample rate fs (code rate carrier-aided).
ChannelStart start_from_code_start(std::int64_t first_sample, double samples_to_code_start, double doppler_hz,
                                   double sample_rate_hz);

// The replica at a sample: which code period (the channel's count, as in CorrelationEpoch::first_code_period) and
// how far into it, and the carrier phase accumulated since the channel's start. What observables are built from.
struct ReplicaState {
  std::int64_t sample_index = 0;
  std::int64_t code_period = 0;
  double code_phase_chips = 0.0;  // [0, 1023) into code_period
  double carrier_phase_cycles = 0.0;
};

// Views on one block of samples (one pointer per antenna, same length, same receiver sample indices).
struct SampleBlockView {
  std::int64_t first_sample = 0;
  int num_samples = 0;
  int num_antennas = 1;
  std::array<const std::complex<float>*, kMaxAntennas> antenna{};
  // The same samples as planar int16 times i16_gain, when i16_gain > 0: the channel then uses the integer
  // correlator (CorrelatorEngine::correlate_i16) on them instead of the float samples.
  std::array<PlanarI16, kMaxAntennas> antenna_i16{};
  double i16_gain = 0.0;
};

class TrackingChannel final {
 public:
  // Throws std::invalid_argument for a configuration outside the documented ranges.
  TrackingChannel(const ChannelConfig& config, const ChannelStart& start);

  // Takes effect at the start of the next epoch (one command per epoch; a later call replaces an unused one).
  void command(const NcoCommand& cmd);
  // From the first code period p >= now with (p - aligned_period) % periods == 0 on, epochs span `periods`
  // code periods (1..20); until then 1-period epochs. periods = 1 returns to 1 ms epochs at once.
  void set_coherent_periods(int periods, std::int64_t aligned_period);

  struct FeedResult {
    int consumed = 0;          // samples of the block used, from `offset` on
    bool epoch_ready = false;  // epoch() holds a new completed epoch
  };
  // Consumes samples of block from `offset` until an epoch completes or the block ends. Call again with
  // offset + consumed until the block is used up; between calls, read epoch() and give the next command.
  // Samples before the channel's start are skipped; a jump forward in sample index (samples lost) is bridged by
  // the NCO (dead reckoning) and drops a partially integrated epoch; the next epoch starts at the next period.
  // block.num_antennas must be at least the configured number of antennas.
  FeedResult feed(const SampleBlockView& block, int offset);

  const CorrelationEpoch& epoch() const { return epoch_; }
  const NcoCommand& current_command() const { return current_; }
  int prn() const { return config_.prn; }
  double sample_rate_hz() const { return config_.sample_rate_hz; }
  const CorrelatorLayout& layout() const { return config_.layout; }
  // Sample index the NCO state refers to (the next sample the channel expects).
  std::int64_t next_sample() const { return nco_sample_; }
  // Sample at which a command given now takes effect: the end of the epoch in progress, else next_sample() (after
  // a gap the epoch actually starts at the next code-period start).
  std::int64_t next_epoch_sample() const { return in_epoch_ ? epoch_end_ : nco_sample_; }
  // The replica's exact NCO state at next_sample() (a pending command is not yet applied).
  ReplicaState replica() const;

 private:
  void apply(const NcoCommand& cmd);
  void begin_epoch();
  void finish_epoch();
  void advance(std::int64_t samples);

  ChannelConfig config_;
  // Tap index in the engine for each role, -1 when off (declared before engine_, whose initialiser sets them).
  int tap_ve_ = -1, tap_e_ = -1, tap_p_ = -1, tap_l_ = -1, tap_vl_ = -1, tap_n_ = -1;
  CorrelatorEngine engine_;
  // The slaves' engine (prompt, then noise when on) when they are correlated apart from the master; its taps'
  // sums sit in sums_[half][a] for a >= 1 in that order.
  std::optional<CorrelatorEngine> slave_engine_;
  int slave_tap_n_ = -1;

  CodePhase code_;        // chips since the channel's start reference (continuous)
  CarrierPhase carrier_;  // cycles since the channel's start (continuous)
  std::int64_t nco_sample_ = 0;
  NcoCommand current_;
  NcoCommand pending_;
  bool has_pending_ = false;
  int coherent_periods_ = 1;
  std::int64_t aligned_period_ = 0;

  bool aligned_ = false;  // the NCO sits at a code-period start (right after an epoch)
  bool in_epoch_ = false;
  std::int64_t epoch_mid_ = 0, epoch_end_ = 0;  // sample indices
  Int128 epoch_period_start_raw_ = 0;
  std::array<std::array<TapSums, kMaxAntennas>, 2> sums_{};  // [half][antenna]
  CorrelationEpoch epoch_;
};

}  // namespace ultratrack::receiver

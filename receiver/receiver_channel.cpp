// SPDX-License-Identifier: GPL-3.0-or-later
#include "receiver/receiver_channel.hpp"

#include <algorithm>
#include <cmath>

#include "receiver/vector_frequency_discriminator.hpp"
#include "signals/gps_constants.hpp"

namespace ultratrack::receiver {

ChannelStart channel_start_from_acquisition(const AcquisitionResult& result, std::int64_t snapshot_first_sample,
                                            std::int64_t start_sample, double fs_hz) {
  ChannelStart s;
  s.sample_index = start_sample;
  s.carrier_frequency_hz = result.doppler_hz;
  const double rate = signals::kCaChipRate_hz * (1.0 + result.doppler_hz / signals::kL1Frequency_hz);
  // Code phase at the snapshot's first sample: the next code start is code_phase_samples later.
  const double elapsed = static_cast<double>(start_sample - snapshot_first_sample) - result.code_phase_samples;
  double phase = std::fmod(elapsed * rate / fs_hz, signals::kCaCodeLength_chips);
  if (phase < 0.0) phase += signals::kCaCodeLength_chips;
  if (phase >= signals::kCaCodeLength_chips) phase = 0.0;
  s.code_phase_chips = phase;
  return s;
}

ReceiverChannel::ReceiverChannel(int prn, const ChannelStart& start, double fs_hz, const ScalarTrackingOptions& options,
                                 int reference_week, bool reference_week_is_signal_week, int record_periods,
                                 int num_antennas)
    : fs_hz_(fs_hz),
      week_trusted_(reference_week_is_signal_week),
      channel_(channel_config(options, prn, fs_hz, num_antennas), start),
      loop_(options, channel_.current_command()),
      nav_(prn, reference_week),
      record_periods_(record_periods < 1 ? 1 : record_periods) {
  last_scalar_ = channel_.current_command();
  if (num_antennas > 1) antenna_phases_.emplace(num_antennas);
}

NcoCommand ReceiverChannel::merged_command() {
  NcoCommand cmd = last_scalar_;
  if (!vector_.vector) return cmd;
  cmd.code_rate_chips_per_s = vector_.code_rate_chips_per_s;
  if (vector_jump_pending_) cmd.code_phase_jump_chips = vector_.code_phase_jump_chips;
  vector_jump_pending_ = false;
  if (vector_carrier_jump_pending_) cmd.carrier_phase_jump_cycles = vector_.carrier_phase_jump_cycles;
  vector_carrier_jump_pending_ = false;
  return cmd;
}

void ReceiverChannel::set_vector_command(const VectorChannelCommand& command) {
  const bool was_vector = vector_.vector;
  vector_ = command;
  // Held until the next measurement (commands come every 20 ms, measurements at the observation rate).
  if (vector_.vector && vector_.carrier_slip) carrier_slip_pending_ = true;
  if (vector_.vector && loop_.state() != TrackingState::kBitSynced && !loop_.coasting()) vector_ = {};
  // Only a channel whose replica the vector loop drives may coast; dropped from it while coasting, it is lost.
  ScalarTrackingControl control;
  control.coasting_allowed = vector_.vector;
  control.filter_driven = vector_.vector && vector_.filter_driven;
  control.clock_steered = vector_.vector && vector_.clock_steered && vector_.carrier == CarrierControl::kAided;
  // Vector FLL: the loop's frequency is the NCO's; the channel's own carrier loop stands still.
  const bool fll =
      vector_.vector && vector_.carrier != CarrierControl::kAided && std::isfinite(vector_.carrier_frequency_hz);
  const bool phase_locked = fll && vector_.carrier == CarrierControl::kFrequencyAndPhase;
  control.carrier = fll ? vector_.carrier : CarrierControl::kAided;
  if (fll) {
    control.carrier_frequency_hz = vector_.carrier_frequency_hz;
    last_scalar_.carrier_frequency_hz = vector_.carrier_frequency_hz;
    previous_aid_hz_ = NAN;  // a later aided command starts aiding afresh
  }
  // Carrier aiding: the predicted Doppler's change since the previous command goes into the PLL's integrator;
  // the command already computed for the next epoch (between epochs) gets it too.
  if (fll) {
  } else if (vector_.vector && std::isfinite(vector_.carrier_frequency_hz)) {
    if (std::isfinite(previous_aid_hz_)) {
      control.aid = CarrierAid::kShift;
      control.aid_delta_hz = vector_.carrier_frequency_hz - previous_aid_hz_;
      last_scalar_.carrier_frequency_hz += control.aid_delta_hz;
    } else {
      control.aid = CarrierAid::kStart;
    }
    previous_aid_hz_ = vector_.carrier_frequency_hz;
  } else {
    previous_aid_hz_ = NAN;
  }
  loop_.apply(control);
  // A filter-driven channel keeps its time tag too: its bits are known and its code-period count is the filter's
  // (bit errors at ~20 dB-Hz, 5 % at 18, fail subframes and would drop the frame lock, hence the tag).
  nav_.hold_time_tag(loop_.coasting() || (vector_.vector && vector_.filter_driven));
  vector_jump_pending_ = vector_.vector && vector_.code_phase_jump_chips != 0.0;
  vector_carrier_jump_pending_ = phase_locked && vector_.carrier_phase_jump_cycles != 0.0;
  // Between epochs the next one starts at once: replace the command it would start with.
  if ((vector_.vector || was_vector) && channel_.next_epoch_sample() == channel_.next_sample())
    channel_.command(merged_command());
}

VectorChannelInput ReceiverChannel::vector_input(const ReceiverClock& clock, int slot) {
  VectorChannelInput in;
  in.slot = slot;
  in.prn = prn();
  in.vector_mode = vector_.vector;
  in.coasting = loop_.coasting();
  in.cn0_dbhz = loop_.cn0_dbhz().value_or(NAN);
  in.code_rate_chips_per_s = channel_.current_command().code_rate_chips_per_s;
  in.carrier_frequency_hz = channel_.current_command().carrier_frequency_hz;
  in.next_epoch_sample = channel_.next_epoch_sample();
  in.synchronised = synchronised() && (week_trusted_ || nav_.decoder().week_known());
  const bool fresh = last_epoch_new_;
  last_epoch_new_ = false;
  if (!in.synchronised) return in;
  const TransmitTimeTag& tag = *nav_.time_tag();
  // Pseudorange of the replica at a sample where it is `chips` into code period `period` (any number of chips:
  // 1023 chips are one code period, 1 ms of transmit time, whatever the Doppler).
  const double tag_age_s = signals::seconds_between(clock.base(), tag.transmit_time);
  const auto pseudorange = [&](std::int64_t sample, std::int64_t period, double chips) {
    const double since_tag =
        static_cast<double>(period - tag.code_period) * signals::kCaCodePeriod_s + chips / signals::kCaChipRate_hz;
    return signals::kSpeedOfLight_mps * (tag_age_s + clock.seconds_since_base(sample) - since_tag);
  };
  const ReplicaState replica = channel_.replica();
  in.replica_pseudorange_m = pseudorange(replica.sample_index, replica.code_period, replica.code_phase_chips);
  const EpochSummary& e = last_epoch_;
  // A filter-driven channel's epochs go to the filter whatever their power while its latest presence window read
  // below 30 dB-Hz (its presence test and the filter's gate judge them; the per-epoch fade gate would keep only
  // the noise peaks of a weak signal). Above, the gate stays: it drops a present 30 dB-Hz epoch with
  // probability ~1e-3 and sees a tunnel at once, where the 1 s presence window takes 1-2 s.
  constexpr double kGateFromDbHz = 30.0;
  const bool present = e.signal_present || (vector_.filter_driven && loop_.presence_cn0_dbhz() < kGateFromDbHz);
  if (!fresh || !e.valid || !e.bit_synced || e.num_code_periods < 2) return in;
  if (e.noise_power > 0.0) {
    const double scale = 1.0 / std::sqrt(0.5 * e.noise_power);  // noise tap: variance 2 sigma^2 (I and Q)
    in.iq_scale = scale;
    const std::array<std::complex<float>, 3> taps{e.early, e.prompt, e.late};
    for (int k = 0; k < 3; ++k) {
      in.iq_i[k] = taps[k].real() * scale;
      in.iq_q[k] = taps[k].imag() * scale;
    }
  }
  in.has_prompt = true;
  in.prompt_integration_time_s = e.num_samples / fs_hz_;
  if (!present) return in;
  in.integration_time_s = in.prompt_integration_time_s;
  in.bit_sign = vector_.filter_driven ? e.bit_sign : 0;
  in.pll_coherent_epochs = std::max(1, loop_.coherent_epochs());
  const int half = e.num_samples / 2;
  in.has_measurement = true;
  in.measurement_sample = e.first_sample + half;
  in.code_error_chips = e.code_error_chips;
  in.replica_pseudorange_mid_m = pseudorange(in.measurement_sample, e.first_code_period,
                                             e.code_phase_start_chips + e.code_rate_chips_per_s * half / fs_hz_);
  constexpr double kChip_m = signals::kSpeedOfLight_mps / signals::kCaChipRate_hz;
  in.measured_pseudorange_m = in.replica_pseudorange_mid_m - e.code_error_chips * kChip_m;
  in.measurement_first_sample = e.first_sample;
  in.replica_carrier_frequency_hz =
      (e.carrier_phase_end_cycles - e.carrier_phase_start_cycles) * fs_hz_ / e.num_samples;
  in.replica_carrier_phase_mid_cycles =
      e.carrier_phase_start_cycles + (e.carrier_phase_end_cycles - e.carrier_phase_start_cycles) * half / e.num_samples;
  in.replica_carrier_phase_next_cycles =
      replica.carrier_phase_cycles +
      in.carrier_frequency_hz * static_cast<double>(in.next_epoch_sample - replica.sample_index) / fs_hz_;
  const EpochSummary& p = previous_epoch_;
  if (p.valid && p.bit_synced && p.num_code_periods == e.num_code_periods &&
      p.first_sample + p.num_samples == e.first_sample) {
    const int p_half = p.num_samples / 2;
    const auto middle_phase = [](const EpochSummary& s, int h) {
      return s.carrier_phase_start_cycles +
             (s.carrier_phase_end_cycles - s.carrier_phase_start_cycles) * h / s.num_samples;
    };
    // Costas phases are bit-insensitive, within +-1/4 cycle: their change is taken within +-1/4 cycle. A channel
    // whose carrier a filter commands and drives, with both bits known, has them wiped: the full phase change
    // (+-1/2 cycle), which at 20-22 dB-Hz stays unbiased where the Costas change reads 0.56-0.78 of the offset.
    const bool wipe = vector_.vector && vector_.filter_driven && vector_.carrier != CarrierControl::kAided &&
                      e.bit_sign != 0 && p.bit_sign != 0;
    const double dphi = wipe ? wiped_phase_change_cycles(p.prompt, e.prompt, e.bit_sign * p.bit_sign)
                             : costas_phase_change_cycles(p.prompt, e.prompt);
    in.doppler_bits_wiped = wipe;
    const std::int64_t p_mid = p.first_sample + p_half;
    in.doppler_interval_s = static_cast<double>(in.measurement_sample - p_mid) / fs_hz_;
    in.measured_doppler_hz = (middle_phase(e, half) - middle_phase(p, p_half) + dphi) / in.doppler_interval_s;
    in.doppler_sample = (p_mid + in.measurement_sample) / 2;
    in.has_doppler = true;
  }
  return in;
}

void ReceiverChannel::after_epoch(const CorrelationEpoch& e, const TrackingReport& report) {
  const bool locked = report.state == TrackingState::kPhaseLocked || report.state == TrackingState::kBitSynced;
  if (antenna_phases_) antenna_phases_->update(e, locked, fs_hz_);
  if (locked) {
    if (!lock_start_sample_) lock_start_sample_ = e.first_sample;
    tracked_s_ += e.integration_time_s;
  }
  if (report.bit) nav_.add_bit(report.bit->soft, report.bit->first_code_period);
  if (nav_.polarity() != polarity_seen_) polarity_fix_ = 1;  // a new subframe resolved the half cycle
  polarity_seen_ = nav_.polarity();
  if (was_coasting_ && report.state == TrackingState::kBitSynced) {
    polarity_votes_left_ = kPolarityVotes;
    polarity_vote_ = 0;
  }
  was_coasting_ = report.state == TrackingState::kCoasting;
  if (polarity_votes_left_ > 0 && epoch_bit_sign_ != 0 && report.state == TrackingState::kBitSynced) {
    polarity_vote_ += (e.master().prompt.real() >= 0.0f ? 1 : -1) * epoch_bit_sign_;
    if (--polarity_votes_left_ == 0 && polarity_vote_ < 0) polarity_fix_ = -polarity_fix_;
  } else {
    check_known_bit(e, report);
  }
  previous_epoch_ = last_epoch_;
  EpochSummary& s = last_epoch_;
  s.valid = true;
  s.bit_synced = report.state == TrackingState::kBitSynced;
  s.first_sample = e.first_sample;
  s.num_samples = e.num_samples;
  s.num_code_periods = e.num_code_periods;
  s.first_code_period = e.first_code_period;
  s.code_phase_start_chips = e.code_phase_start_chips;
  s.code_rate_chips_per_s = e.code_rate_chips_per_s;
  s.carrier_phase_start_cycles = e.carrier_phase_start_cycles;
  s.carrier_phase_end_cycles = e.carrier_phase_end_cycles;
  s.early = e.master().early;
  s.prompt = e.master().prompt;
  s.late = e.master().late;
  s.code_error_chips = report.code_error_chips;
  s.bit_sign = epoch_bit_sign_;
  // A fade shows in one epoch's prompt long before the C/N0 estimate (0.2 s window) follows: vector tracking
  // takes no measurement from an epoch whose |P|^2 / mean |noise|^2 is below 1 + 10^(2.5) T (25 dB-Hz; noise
  // alone passes with probability exp(-7.3) = 0.07 % at T = 20 ms; a 45 dB-Hz signal sits ~19 dB above it).
  const double n2 = std::norm(std::complex<double>(e.master().noise));
  if (e.num_code_periods != noise_periods_ || noise_power_ <= 0.0) {
    noise_periods_ = e.num_code_periods;
    noise_power_ = n2;
  } else {
    noise_power_ += 0.05 * (n2 - noise_power_);
  }
  s.noise_power = noise_power_;
  s.signal_present = std::norm(std::complex<double>(s.prompt)) > (1.0 + 316.0 * e.integration_time_s) * noise_power_;
  last_epoch_new_ = true;
}

TrackingRecord ReceiverChannel::record(const CorrelationEpoch& e, const TrackingReport& report) const {
  TrackingRecord r;
  r.prn = e.prn;
  r.sample_index = e.first_sample;
  r.prompt = e.master().prompt;
  r.integration_ms = e.num_code_periods;
  r.cn0_dbhz = report.cn0_dbhz ? *report.cn0_dbhz : NAN;
  r.doppler_hz = e.carrier_frequency_hz;
  r.code_phase_chips = e.code_phase_start_chips;
  r.state = report.state;
  r.pli = report.pli;
  r.phase_locked = report.phase_locked;
  r.frame_synced = nav_.synchronised();
  r.coherent_ms = report.loop_integration_ms;
  return r;
}

// The running check (receiver/nav_bit_check.hpp) of a bit wiped by its prediction against the prompt's sign
// (polarity resolved), phase-locked on 20 ms; a trip stops the decoded source until new data re-arm it, while
// the oracle's contradictions are only counted.
void ReceiverChannel::check_known_bit(const CorrelationEpoch& e, const TrackingReport& report) {
  NavBitPredictor& predictor = nav_.bit_predictor();
  if (predictor.take_new_data()) bit_check_.rearm();
  if (epoch_bit_sign_ == 0 || report.state != TrackingState::kBitSynced || e.num_code_periods != 20) return;
  const bool agrees = (e.master().prompt.real() >= 0.0f ? 1 : -1) == epoch_bit_sign_;
  const double cn0 = report.cn0_dbhz ? *report.cn0_dbhz : NAN;
  if (bit_check_.add(epoch_bit_word_, agrees, cn0) && predictor.source() == NavBitSource::kDecoded) {
    predictor.stop();
    ++bit_check_.counts().sources_stopped;
  }
}

NavBitCounts ReceiverChannel::nav_bit_counts() const {
  NavBitCounts c = bit_check_.counts();
  c.nav_words_agreed += nav_.bit_predictor().nav_words_agreed();
  c.nav_words_disagreed += nav_.bit_predictor().nav_words_disagreed();
  c.oracle = oracle_used_;
  return c;
}

// The signs of the bits from epoch e's on (20 ms epochs on bit edges), while the predictor knows them: transmit
// time from the frame's time tag, sign = polarity x (+1 for bit 0). Not while a vector loop drives the replica.
KnownBits ReceiverChannel::known_bits(const CorrelationEpoch& e, int wanted) {
  KnownBits k;
  epoch_bit_sign_ = 0;
  // Filter-driven channels always want the epoch's own bit (the filter's wipe-off), and long sums when weak.
  const bool driven = vector_.vector && vector_.filter_driven;
  if (driven) wanted = std::max(wanted, 1);
  if (wanted <= 0 || (vector_.vector && !driven) || e.num_code_periods != 20 || !nav_.synchronised()) return k;
  const TransmitTimeTag& tag = *nav_.time_tag();
  NavBitPredictor& predictor = nav_.bit_predictor();
  if (supplied_ && !supplied_tried_) {
    supplied_tried_ = true;  // selected once, near the channel's start (as the simulator selects at its start)
    const signals::GpsTime start =
        signals::add_seconds(tag.transmit_time, -1e-3 * static_cast<double>(tag.code_period));
    predictor.supply_navigation(prn(), supplied_->ephemerides, supplied_->klobuchar, supplied_->utc, start);
  }
  for (int i = 0; i < wanted; ++i) {
    const std::int64_t p = e.first_code_period + 20 * static_cast<std::int64_t>(i);
    const signals::GpsTime t = signals::add_seconds(tag.transmit_time, 1e-3 * static_cast<double>(p - tag.code_period));
    const auto bit = predictor.bit_at(t);
    if (i == 0) {  // the bit's word, from its middle (t may be a hair before its edge)
      const signals::GpsTime mid = signals::add_seconds(t, 0.01);
      epoch_bit_word_ =
          static_cast<std::int64_t>(mid.week) * 1008000 + static_cast<std::int64_t>(std::floor(mid.tow_s / 0.6));
    }
    if (!bit) break;
    if (i == 0) k.sign = (*bit != 0 ? -1 : 1) * nav_.polarity() * polarity_fix_;
    ++k.ahead;
  }
  epoch_bit_sign_ = k.sign;
  ++(k.sign != 0 ? bit_check_.counts().bits_wiped : bit_check_.counts().bits_unknown);
  oracle_used_ = oracle_used_ || (predictor.supplied() && predictor.source() == NavBitSource::kOracle);
  return k;
}

std::optional<ChannelMeasurement> ReceiverChannel::measure() {
  if (!synchronised() || !(week_trusted_ || nav_.decoder().week_known())) return std::nullopt;
  // No signal (coasting, or a sudden fade of a channel no vector loop holds: receiver/fade_detector.hpp; a vector
  // loop's channels have its presence test and coasting instead): nothing measured; the track resumes as a new one
  // (loss of lock).
  if (loop_.coasting() || (!vector_.vector && loop_.signal_faded())) {
    reported_ = false;
    return std::nullopt;
  }
  const TransmitTimeTag& tag = *nav_.time_tag();
  const ReplicaState replica = channel_.replica();
  ChannelMeasurement m;
  m.prn = prn();
  m.tag_time = tag.transmit_time;
  // Each code period is 1 ms and each chip 1/1.023 MHz of transmit time, whatever the Doppler.
  m.since_tag_s = static_cast<double>(replica.code_period - tag.code_period) * signals::kCaCodePeriod_s +
                  replica.code_phase_chips / signals::kCaChipRate_hz;
  // Inverted bits mean the Costas loop sits half a cycle from the true carrier phase.
  const double half = nav_.polarity() < 0 ? 0.5 : 0.0;
  // The replica phase follows +Doppler, i.e. -range / lambda; RINEX phase follows +range.
  m.carrier_phase_cycles = -(replica.carrier_phase_cycles + half);
  m.doppler_hz = channel_.current_command().carrier_frequency_hz;
  m.cn0_dbhz = loop_.cn0_dbhz().value_or(0.0);
  m.lock_time_s = lock_start_sample_ ? static_cast<double>(replica.sample_index - *lock_start_sample_) / fs_hz_ : 0.0;
  m.new_track = !reported_;
  // Vector FLL: the phase is the NCO's accumulated Doppler, which drifts from the signal's by the integral of the
  // filter's frequency error (no phase lock): every epoch carries the loss-of-lock flag. A vector PLL's phase is
  // locked; its first epoch after unlocked ones starts a new arc (its phase was re-aligned): flagged too.
  const bool unlocked = loop_.carrier_commanded() && !loop_.carrier_phase_locked();
  // A slip the vector loop reported (VectorChannelCommand::carrier_slip) flags this epoch's phase as well.
  m.phase_unlocked = unlocked || last_phase_unlocked_ || carrier_slip_pending_;
  carrier_slip_pending_ = false;
  last_phase_unlocked_ = unlocked;
  reported_ = true;
  return m;
}

}  // namespace ultratrack::receiver

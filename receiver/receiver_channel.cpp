#include "receiver/receiver_channel.hpp"

#include <cmath>

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
  if (num_antennas > 1) antenna_phases_.emplace(num_antennas);
}

void ReceiverChannel::after_epoch(const CorrelationEpoch& e, const TrackingReport& report) {
  const bool locked = report.state == TrackingState::kPhaseLocked || report.state == TrackingState::kBitSynced;
  if (antenna_phases_) antenna_phases_->update(e, locked, fs_hz_);
  if (locked) {
    if (!lock_start_sample_) lock_start_sample_ = e.first_sample;
    tracked_s_ += e.integration_time_s;
  }
  if (report.bit) nav_.add_bit(report.bit->soft, report.bit->first_code_period);
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
  return r;
}

std::optional<ChannelMeasurement> ReceiverChannel::measure() {
  if (!synchronised() || !(week_trusted_ || nav_.decoder().week_known())) return std::nullopt;
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
  m.lock_time_s =
      lock_start_sample_ ? static_cast<double>(replica.sample_index - *lock_start_sample_) / fs_hz_ : 0.0;
  m.new_track = !reported_;
  reported_ = true;
  return m;
}

}  // namespace ultratrack::receiver

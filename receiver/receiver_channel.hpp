// SPDX-License-Identifier: GPL-3.0-or-later
// One receiver channel: a satellite's TrackingChannel closed by ScalarTracking (which assembles the 20 ms
// navigation bits) and its NavigationDataChannel (frame sync, LNAV decoding, transmit-time tag). At any
// sample the channel has reached it gives the observables' raw material: the transmit time of the replica
// (time tag + whole code periods + code phase / chip rate) and the carrier phase with the Costas half cycle
// resolved by the frame polarity. Units: seconds, chips, cycles, Hz; sample indices on the receiver's clock.
#pragma once

#include <cmath>
#include <complex>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "receiver/acquisition.hpp"
#include "receiver/antenna_phase_tracker.hpp"
#include "receiver/nav_bit_check.hpp"
#include "receiver/nav_bit_source.hpp"
#include "receiver/navigation_data_channel.hpp"
#include "receiver/receiver_clock.hpp"
#include "receiver/scalar_tracking.hpp"
#include "receiver/tracking_channel.hpp"
#include "receiver/vector_loop.hpp"
#include "signals/gps_time.hpp"

namespace ultratrack::receiver {

// Where a satellite's replica starts when acquisition searched samples from snapshot_first_sample on but
// tracking begins later, at start_sample: the code phase is carried forward at the Doppler-scaled chip rate
// 1.023 MHz (1 + f_d / f_L1) over the samples in between (the carrier phase restarts at 0: it is arbitrary).
ChannelStart channel_start_from_acquisition(const AcquisitionResult& result, std::int64_t snapshot_first_sample,
                                            std::int64_t start_sample, double fs_hz);

// One tracking.csv row: the prompt and loop state of a channel at the start of an epoch.
struct TrackingRecord {
  int prn = 0;
  std::int64_t sample_index = 0;  // first sample of the epoch
  std::complex<float> prompt{};   // unnormalised correlator sum
  int integration_ms = 1;
  double cn0_dbhz = NAN;          // NaN before the first estimate
  double doppler_hz = 0.0;        // replica carrier frequency at baseband
  double code_phase_chips = 0.0;  // replica code phase into the period at the epoch start
  TrackingState state = TrackingState::kPullIn;
  double pli = 0.0;
  bool phase_locked = false;
  bool frame_synced = false;
  int coherent_ms = 1;  // the loops' integration time (N x 20 ms with data wipe-off)
};

// Broadcast navigation supplied to the receiver (a nav file): the source of known bits for data wipe-off
// (NavBitPredictor::supply_navigation), shared read-only by the channels.
struct SuppliedNavigation {
  std::vector<signals::Ephemeris> ephemerides;
  signals::KlobucharParameters klobuchar;
  signals::UtcParameters utc;
};

// What a synchronised channel measures at the sample it has reached.
struct ChannelMeasurement {
  int prn = 0;
  signals::GpsTime tag_time;          // transmit time of the tagged subframe start
  double since_tag_s = 0.0;           // replica's transmit time - tag_time (code periods + code phase)
  double carrier_phase_cycles = 0.0;  // RINEX sense (grows with range), half cycle resolved
  double doppler_hz = 0.0;            // positive when approaching
  double cn0_dbhz = 0.0;
  double lock_time_s = 0.0;
  bool new_track = false;       // first measurement of this track (RINEX loss of lock)
  bool phase_unlocked = false;  // the carrier phase is not phase-locked (vector FLL), or is the first locked one after
                                // such (vector PLL re-lock): RINEX loss of lock
};

class ReceiverChannel {
 public:
  // reference_week_is_signal_week: the reference week is known to be the signal's (see ReceiverOptions);
  // otherwise measure() waits until this channel's subframe 1 has given the week.
  // num_antennas > 1: every antenna is correlated against the master's replica and an AntennaPhaseTracker
  // follows each one's phase against the master.
  ReceiverChannel(int prn, const ChannelStart& start, double fs_hz, const ScalarTrackingOptions& options,
                  int reference_week, bool reference_week_is_signal_week, int record_periods, int num_antennas = 1);

  // Consumes a block (samples before next_sample() are skipped); calls on_record(const TrackingRecord&) once
  // every record_periods code periods. Allocates nothing.
  template <class OnRecord>
  void feed(const SampleBlockView& block, OnRecord&& on_record) {
    int offset = 0;
    while (offset < block.num_samples) {
      const auto r = channel_.feed(block, offset);
      offset += r.consumed;
      if (r.epoch_ready) {
        const CorrelationEpoch& e = channel_.epoch();
        const TrackingReport report = loop_.update(e, known_bits(e, loop_.known_bits_wanted()));
        last_scalar_ = report.command;
        // vector mode only while bit-synced or coasting on the vector loop's prediction
        if (report.state != TrackingState::kBitSynced && report.state != TrackingState::kCoasting) {
          vector_ = {};
          previous_aid_hz_ = NAN;
          ScalarTrackingControl released = loop_.control();
          released.carrier = CarrierControl::kAided;
          loop_.apply(released);
        }
        channel_.command(merged_command());
        if (report.set_coherent) channel_.set_coherent_periods(report.coherent_periods, report.aligned_period);
        after_epoch(e, report);
        const std::int64_t p0 = e.first_code_period;
        if (floor_div(p0 + e.num_code_periods - 1, record_periods_) != floor_div(p0 - 1, record_periods_))
          on_record(record(e, report));
      }
    }
  }

  int prn() const { return channel_.prn(); }
  TrackingState state() const { return loop_.state(); }
  bool lost() const { return loop_.state() == TrackingState::kLost; }
  std::int64_t next_sample() const { return channel_.next_sample(); }
  std::optional<double> cn0_dbhz() const { return loop_.cn0_dbhz(); }
  // Synchronised: bit sync, frame sync and a transmit-time tag; measurement() is then available.
  // Coasting channels stay synchronised (their bit edges and time tag are kept) but give no measurements.
  bool synchronised() const {
    return (loop_.state() == TrackingState::kBitSynced || loop_.state() == TrackingState::kCoasting) &&
           nav_.synchronised();
  }
  bool coasting() const { return loop_.coasting(); }
  // Known bits for data wipe-off: from the decoded subframes, and the nav file (from the first time tag on;
  // nullptr: none) as `source` says (receiver/nav_bit_source.hpp). Before the first epoch.
  void supply_navigation(std::shared_ptr<const SuppliedNavigation> navigation,
                         NavBitSource source = NavBitSource::kDecoded) {
    supplied_ = std::move(navigation);
    nav_.bit_predictor().set_source(source);
  }
  // This channel's data wipe-off so far: bits wiped, unknown, checked against the signal and contradicted.
  NavBitCounts nav_bit_counts() const;
  // The measurement at next_sample(); nothing unless synchronised() and the time tag's week is known.
  // Marks the track as reported.
  std::optional<ChannelMeasurement> measure();
  NavigationDataChannel& navigation() { return nav_; }
  const NavigationDataChannel& navigation() const { return nav_; }
  double tracked_time_s() const { return tracked_s_; }
  // Vector tracking (receiver/vector_loop.hpp), between blocks on the engine's thread. vector_input: the
  // channel at the sample it has reached, with the latest correlation epoch's measurements if not yet handed
  // over (then marked handed over). set_vector_command: in vector mode the loop's code rate replaces the DLL's
  // from the next epoch start on, and its code phase jump is applied there once.
  VectorChannelInput vector_input(const ReceiverClock& clock, int slot);
  void set_vector_command(const VectorChannelCommand& command);
  bool vector_mode() const { return vector_.vector; }
  // The between-antenna phases (nullptr with one antenna).
  AntennaPhaseTracker* antenna_phases() { return antenna_phases_ ? &*antenna_phases_ : nullptr; }

 private:
  static std::int64_t floor_div(std::int64_t a, std::int64_t b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }
  void after_epoch(const CorrelationEpoch& e, const TrackingReport& report);
  TrackingRecord record(const CorrelationEpoch& e, const TrackingReport& report) const;
  NcoCommand merged_command();
  KnownBits known_bits(const CorrelationEpoch& e, int wanted);
  void check_known_bit(const CorrelationEpoch& e, const TrackingReport& report);

  // What vector tracking needs of a completed epoch.
  struct EpochSummary {
    bool valid = false;
    bool bit_synced = false;
    std::int64_t first_sample = 0;
    int num_samples = 0;
    int num_code_periods = 1;
    std::int64_t first_code_period = 0;
    double code_phase_start_chips = 0.0, code_rate_chips_per_s = 0.0;
    double carrier_phase_start_cycles = 0.0, carrier_phase_end_cycles = 0.0;
    std::complex<float> early{}, prompt{}, late{};
    double noise_power = 0.0;  // noise_power_ after this epoch
    double code_error_chips = 0.0;
    bool signal_present = false;  // this epoch's prompt power well above the noise tap's (see after_epoch)
    int bit_sign = 0;             // the known bit's sign used for this epoch (0: none)
  };
  double noise_power_ = 0.0;  // running mean of |noise tap|^2 for the current epoch length
  int noise_periods_ = 0;
  EpochSummary last_epoch_, previous_epoch_;
  bool last_epoch_new_ = false;
  VectorChannelCommand vector_;
  bool vector_jump_pending_ = false;
  bool vector_carrier_jump_pending_ = false;  // vector PLL: carrier_phase_jump_cycles not applied yet
  bool last_phase_unlocked_ = false;          // the previous measurement's carrier phase was not phase-locked
  bool carrier_slip_pending_ = false;         // a vector command said carrier_slip since the last measurement
  double previous_aid_hz_ = NAN;              // the last command's predicted Doppler (carrier aiding)
  NcoCommand last_scalar_;
  int epoch_bit_sign_ = 0;           // the known bit of the epoch being updated (known_bits)
  std::int64_t epoch_bit_word_ = 0;  // its LNAV word number (transmit time / 0.6 s)
  NavBitCheck bit_check_;
  bool oracle_used_ = false;  // the oracle source gave this channel's bits
  // After a re-lock from coasting the Costas loop may sit half a cycle from where the frame's polarity was
  // found: the first kPolarityVotes known-bit epochs vote (sign of I_P x known sign) and a negative vote inverts
  // the known signs until a new subframe gives the polarity again.
  static constexpr int kPolarityVotes = 10;
  int polarity_fix_ = 1, polarity_votes_left_ = 0, polarity_vote_ = 0, polarity_seen_ = 1;
  bool was_coasting_ = false;

  double fs_hz_;
  bool week_trusted_;  // the reference week is the signal's: time tags usable before subframe 1
  TrackingChannel channel_;
  ScalarTracking loop_;
  NavigationDataChannel nav_;
  int record_periods_;
  std::optional<std::int64_t> lock_start_sample_;
  bool reported_ = false;
  double tracked_s_ = 0.0;
  std::optional<AntennaPhaseTracker> antenna_phases_;
  std::shared_ptr<const SuppliedNavigation> supplied_;
  bool supplied_tried_ = false;
};

}  // namespace ultratrack::receiver

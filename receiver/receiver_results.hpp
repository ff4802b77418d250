// SPDX-License-Identifier: GPL-3.0-or-later
// What the receiver engine reports: the observer it calls with its results as they happen, and the counts it
// keeps over a run (per satellite and overall). Units: samples, seconds, metres, radians, dB-Hz.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "receiver/acquisition.hpp"
#include "receiver/antenna_phase.hpp"
#include "receiver/observables.hpp"
#include "receiver/pvt.hpp"
#include "receiver/receiver_channel.hpp"

namespace ultratrack::receiver {

// Receives what the engine produces, synchronously, from process(), on the thread that calls process().
// Default: ignore.
class ReceiverObserver {
 public:
  virtual ~ReceiverObserver() = default;
  virtual void on_tracking(const TrackingRecord&) {}
  virtual void on_acquisition(std::int64_t /*snapshot_first_sample*/, const std::vector<AcquisitionResult>&) {}
  virtual void on_observations(const ObservationEpoch&) {}
  virtual void on_fix(const PvtSolution&, const ObservationEpoch&) {}
  // Multi-antenna receivers (num_antennas > 1): every antenna's phase per satellite, after each epoch's fix.
  virtual void on_antenna_phases(const AntennaPhaseEpoch&) {}
};

// Per-satellite counts over the run (index = PRN).
struct SatelliteStats {
  int acquisitions = 0;                // times detected and given a channel
  int losses = 0;                      // times its channel lost lock and was released
  double tracked_s = 0.0;              // time phase-locked
  double cn0_sum_dbhz = 0.0;           // over observation epochs
  double tracking_cn0_sum_dbhz = 0.0;  // over tracking records with an estimate (every 20 ms)
  int tracking_cn0_count = 0;
  int observations = 0;  // observation epochs with a pseudorange
  int used_in_fixes = 0;
  bool frame_synced = false;
  bool ephemeris_decoded = false;
  NavBitCounts nav_bits;  // of its released channels (ReceiverEngine::nav_bit_counts adds the live one)
};

struct ReceiverStats {
  std::int64_t first_sample = 0;  // first sample processed
  std::int64_t samples_processed = 0;
  std::optional<std::int64_t> first_fix_sample;
  int fixes = 0;
  int fixes_rejected_gdop = 0;  // epochs whose solution had a GDOP above PvtOptions::max_gdop (no fix)
  int observation_epochs = 0;
  int clock_jumps = 0;
  Eigen::Vector3d sum_r_e_m = Eigen::Vector3d::Zero();  // for the mean fix
  double sum_lat_rad = 0.0, sum_lon_rad = 0.0, sum_height_m = 0.0;
  std::array<SatelliteStats, 33> satellites{};
};

}  // namespace ultratrack::receiver

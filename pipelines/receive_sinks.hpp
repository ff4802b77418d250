// SPDX-License-Identifier: GPL-3.0-or-later
// Where a receive pipeline's own epochs go (the receiver's, solution.csv and the rest, go to its
// receiver::ReceiverObserver): the GNSS/INS navigation solution after each IMU step (nav.csv), the vector
// filter's epochs (vector.csv, vector_state.csv) and the ultra-tight loop's (ultratight.csv). Every method has an
// empty default: a sink takes what it needs. pipelines/receive_csv_files.hpp writes the files.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "fusion/vector_tracking.hpp"
#include "ins/nav_state.hpp"
#include "pipelines/nav_sigma.hpp"

namespace ultratrack::pipelines {

// One channel at one ultra-tight vector epoch (a row of ultratight.csv). NaN: not available this epoch.
struct UltraTightChannelLog {
  int prn = 0;
  bool synchronised = false, ultratight = false, coasting = false;  // ultratight: commanded by the loop
  double coast_s = 0.0, cn0_dbhz = 0.0;
  double measured_pseudorange_m = 0.0, predicted_pseudorange_m = 0.0;  // continuous receiver clock
  double measured_doppler_hz = 0.0, predicted_doppler_hz = 0.0, replica_carrier_hz = 0.0;
  double replica_code_rate_chips_per_s = 0.0, predicted_code_rate_chips_per_s = 0.0, code_jump_chips = 0.0;
  bool updated = false, accepted = false;  // the filter's update from this satellite, and its gate
  double nis = 0.0;
  std::array<double, 6> innovation{};
  double carrier_offset_hz = 0.0;  // replica carrier minus the predicted Doppler
  bool carrier_runaway = false;    // left out of the filter and its phase flagged
};

struct UltraTightEpochLog {
  std::int64_t sample = 0;  // the vector epoch's receiver sample
  double time_s = 0.0;      // sample / fs
  std::vector<UltraTightChannelLog> channels;
};

class ReceiveSink {
 public:
  virtual ~ReceiveSink() = default;
  // Loose, tight, ultra-tight: the solution at the IMU position, at strictly increasing nav.t_s.
  virtual void on_navigation(const ins::NavState& /*nav*/, const NavSigma& /*sigma*/) {}
  // Vector: every vector epoch of the filter (channels in vector mode or not).
  virtual void on_vector_epoch(const fusion::VectorEpochLog& /*epoch*/) {}
  // Ultra-tight: every vector epoch after the hand-over, one entry per channel.
  virtual void on_ultratight_epoch(const UltraTightEpochLog& /*epoch*/) {}
};

}  // namespace ultratrack::pipelines

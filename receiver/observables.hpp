// SPDX-License-Identifier: GPL-3.0-or-later
// Raw GNSS observables at a common receive epoch, as the receiver measures them against its own clock:
// what the PVT, the fusion filters and the RINEX writer consume. Units: metres, cycles, Hz, dB-Hz, s.
#pragma once

#include <cstdint>
#include <vector>

#include "signals/gps_time.hpp"

namespace ultratrack::receiver {

struct Observation {
  int prn = 0;
  double pseudorange_m = 0.0;  // c * (receive time by the receiver clock - transmit time)
  double carrier_phase_cycles =
      0.0;  // accumulated, continuous while locked (RINEX sign: grows with the range, like the pseudorange)
  double doppler_hz = 0.0;  // positive when the range shrinks
  double cn0_dbhz = 0.0;
  double lock_time_s = 0.0;         // time since carrier lock was (re)gained
  bool loss_of_lock = false;        // lock was lost since the previous epoch: the phase may have slipped
  bool half_cycle_resolved = true;  // false until the bit polarity (preamble) resolves the Costas ambiguity
};

struct ObservationEpoch {
  signals::GpsTime receive_time;  // by the receiver clock
  std::int64_t sample_index = 0;  // the receiver's master clock
  std::vector<Observation> observations;
};

}  // namespace ultratrack::receiver

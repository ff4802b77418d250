// SPDX-License-Identifier: GPL-3.0-or-later
// Settings of the whole scalar receiver (receiver_engine.hpp): acquisition, tracking, channel allocation,
// observation rate and PVT. Defaults suit real sky data at L1 C/A. Units: Hz, seconds, samples at the edge.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "receiver/acquisition.hpp"
#include "receiver/nav_bit_source.hpp"
#include "receiver/pvt.hpp"
#include "receiver/scalar_tracking.hpp"

namespace ultratrack::receiver {

struct ReceiverOptions {
  double fs_hz = 0.0;      // complex baseband sample rate (after IF removal), Hz
  int channels = 12;       // tracking channels, 1..32
  std::vector<int> prns;   // PRNs to search; empty = 1..32
  int reference_week = 0;  // full GPS week within +-512 weeks of the signal (10-bit WN)
  // True when reference_week IS the signal's week (from a nav file, the user or a scenario): time tags are
  // then usable before subframe 1 gives the week. False for a guess such as the build date: a channel's
  // measurements wait for its subframe 1.
  bool reference_week_is_signal_week = false;
  double observation_interval_s = 0.1;    // common receive epochs (observables, PVT), rounded to samples
  double reacquisition_interval_s = 5.0;  // a fresh snapshot for missing PRNs this often (with free channels)
  // A re-acquisition searches on a worker thread while the channels track; its satellites join the channels
  // this long after the snapshot ends (a fixed sample point, so results do not depend on thread timing).
  // With no channel tracking (the cold start) they join at once. [0, 10] s.
  double reacquisition_latency_s = 1.0;
  // Blind (unassisted) re-acquisitions while some channel tracks search at most this many missing PRNs per
  // snapshot, round robin (each search keeps its full sensitivity; a PRN comes round every few snapshots).
  // 0: all of them every time. The cold start always searches every PRN.
  int blind_prns_per_snapshot = 8;
  // Low duty cycle once the receiver can fix (a fix, or >= 4 channels in use): absent satellites are then ones
  // that rise or re-appear, so a blind re-acquisition takes only as many missing PRNs as keep each searched
  // once per blind_revisit_s (round robin, at most blind_prns_per_snapshot), and PRNs whose channel lost lock
  // within the last blind_revisit_s every time. Worst case from a satellite's appearance (at a C/N0 the search
  // detects) to its channel: blind_revisit_s + 2 (reacquisition_interval_s + reacquisition_latency_s) + 0.2 s
  // (docs/performance.md). 0: off (blind_prns_per_snapshot every time). [0, 3600] s.
  double blind_revisit_s = 60.0;
  // Satellites predicted below assisted_elevation_min_deg (from an ephemeris or a decoded almanac, at the last
  // fix or at approximate_r_e_m before one) are not searched blindly; one of them, round robin, is checked
  // this often in case the prediction is wrong. [1, 3600] s.
  double hidden_prn_check_interval_s = 60.0;
  // A rough receiver position (ECEF, metres; within ~100 km) for visibility predictions before the first fix.
  std::optional<std::array<double, 3>> approximate_r_e_m;
  int threads = 0;  // worker threads including the caller's, 1..256; 0 = hardware threads
  // Channels correlate int16 copies of each block (the integer kernel, ~1.8x the float one; loss < 0.01 dB):
  // the gain to int16 is fixed once from the cold start's snapshot (noise rms -> 2048). False: float kernel.
  bool integer_correlator = true;
  double assisted_doppler_half_width_hz = 600.0;  // assisted search window around the predicted Doppler
  double assisted_elevation_min_deg = -5.0;       // assisted search skips satellites below this
  double initial_travel_time_s = 0.068;           // receiver clock set to (latest transmit time + this) at first sync
  double clock_jump_threshold_s = 1e-3;           // after a fix, a receiver clock error above this is removed (a jump)
  double tracking_record_interval_s = 0.02;       // tracking.csv rows per channel
  int num_antennas = 1;                           // antennas on one clock (1..kMaxAntennas); antenna 0 is acquired on
  double smoothing_window_s = 10.0;               // Hatch filter for the PVT's pseudoranges; 0 = off (raw)
  // Navigation bits data wipe-off may use (receiver/nav_bit_source.hpp): decoded from the signal (a nav file's
  // words once a decoded copy agrees), or the nav file re-encoded as our simulator does (oracle, studies only).
  NavBitSource nav_bits = NavBitSource::kDecoded;
  AcquisitionOptions acquisition;  // fs_hz is taken from fs_hz above
  ScalarTrackingOptions tracking;
  PvtOptions pvt;

  // Acquisition: 4 ms coherent x 5 non-coherent (a 20 ms snapshot). Against 1 ms x 10 it finds every satellite
  // of a 35 dB-Hz scenario on the first snapshot (1 ms x 10 missed 4 of 7, found 5-10 s later); it costs ~4x
  // more per search (Doppler step 167 Hz), about 25 % of a 60 s run's time while blind re-acquisition runs.
  ReceiverOptions() {
    acquisition.coherent_ms = 4;
    acquisition.noncoherent = 5;
  }
  // Empty when valid, else the first problem found.
  // True when the options fit together; otherwise false and *why (when given) says which setting and why.
  bool IsValid(std::string* why) const;
};

}  // namespace ultratrack::receiver

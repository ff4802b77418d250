// SPDX-License-Identifier: GPL-3.0-or-later
// The seam between the multi-antenna receiver and the attitude solver: at one receive epoch, for each satellite,
// the carrier phase of every antenna measured against the master antenna's one replica (all antennas sampled on
// one clock), the line of sight, and the slip flags. Units: cycles of L1, metres, dB-Hz; frames in the names.
//
// Between two antennas of one satellite the receiver clock, the satellite clock, the atmosphere and the navigation
// bit cancel: carrier_phase_cycles[k] - carrier_phase_cycles[0] = -(b_k . los) / lambda + N_k + line bias + noise
// (minus: an antenna nearer the satellite sees a shorter range), with b_k the ECEF baseline from the master to
// antenna k and N_k an integer that stays fixed while no slip flag is raised for antenna k.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

#include "receiver/correlation_epoch.hpp"
#include "signals/gps_time.hpp"

namespace ultratrack::receiver {

struct AntennaPhaseObservation {
  int prn = 0;
  // Unit vector from the master antenna to the satellite, ECEF (from the ephemeris at transmit time, Sagnac
  // rotated), and the satellite's elevation there, rad.
  Eigen::Vector3d los_e = Eigen::Vector3d::Zero();
  double elevation_rad = 0.0;
  int num_antennas = 1;
  // Accumulated carrier phase per antenna, cycles, RINEX sense (grows with range), continuous while no slip.
  std::array<double, kMaxAntennas> carrier_phase_cycles{};
  std::array<double, kMaxAntennas> cn0_dbhz{};
  // Raised when antenna k's phase may have jumped by whole cycles since the previous epoch (lock lost on that
  // antenna, a between-antenna phase-rate jump, a blockage): its ambiguity for this satellite must restart.
  std::array<bool, kMaxAntennas> slip{};
  // False while antenna k has no usable phase this epoch (blocked, C/N0 below threshold): leave it out.
  std::array<bool, kMaxAntennas> usable{};
};

struct AntennaPhaseEpoch {
  signals::GpsTime receive_time;
  std::int64_t sample_index = 0;
  // The master antenna's position, ECEF, m (from the PVT): sets the local NED frame of the attitude.
  Eigen::Vector3d master_position_e = Eigen::Vector3d::Zero();
  std::vector<AntennaPhaseObservation> satellites;
};

}  // namespace ultratrack::receiver

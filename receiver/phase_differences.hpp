// SPDX-License-Identifier: GPL-3.0-or-later
// Between-antenna single differences and between-satellite double differences of carrier phase for a rigid antenna
// array, with the full (correlated) DD covariance. Units: cycles of L1; geometry rows in cycles per metre of ECEF
// baseline. Sign: RINEX phase (grows with range), so SD_k^s = -(u_s . b_k) / lambda + N_k^s + line bias_k.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "receiver/antenna_phase.hpp"

namespace ultratrack::receiver {

// Antenna k minus the master, cycles.
inline double single_difference_cycles(const AntennaPhaseObservation& sat, int antenna) {
  return sat.carrier_phase_cycles[static_cast<std::size_t>(antenna)] - sat.carrier_phase_cycles[0];
}

// d SD / d b_e for a satellite: -u_s^T / lambda (cycles per metre).
Eigen::RowVector3d single_difference_geometry(const AntennaPhaseObservation& sat);

struct DdRow {
  int antenna = 0;  // baseline master -> antenna
  int prn = 0;
  int ref_prn = 0;
  std::size_t sat = 0, ref_sat = 0;  // indices into the satellite list the set was formed from
};

// Rows are grouped by baseline (antenna 1 first); within one, satellites in input order, the reference left out.
struct DoubleDifferences {
  std::vector<DdRow> rows;
  Eigen::VectorXd dd_cycles;   // SD_k^s - SD_k^ref
  Eigen::MatrixXd geometry;    // rows x 3: d DD / d b_k (ECEF), cycles per metre
  Eigen::MatrixXd covariance;  // rows x rows, cycles^2: the master's and the reference's noise correlate rows
  std::vector<int> baseline_begin, baseline_count;  // per antenna (index 0 unused): first row, number of rows
  int num_antennas = 0;
};

// include(s, k): whether satellite s's phase on antenna k (k >= 1) enters the DDs (its master phase is then used
// too). The reference satellite of each baseline is the highest-elevation included satellite. phase_sigma_cycles:
// 1-sigma of one antenna's phase, all antennas and satellites independent.
template <typename Include>
DoubleDifferences form_double_differences(const std::vector<const AntennaPhaseObservation*>& sats, int num_antennas,
                                          double phase_sigma_cycles, Include include);

// Same, with explicit references per antenna (ref_sat[k] an index into sats, -1: baseline left out) and the rows
// limited to include(s, k).
DoubleDifferences form_double_differences_with_references(const std::vector<const AntennaPhaseObservation*>& sats,
                                                          int num_antennas, double phase_sigma_cycles,
                                                          const std::vector<int>& ref_sat,
                                                          const std::vector<std::vector<bool>>& included);

template <typename Include>
DoubleDifferences form_double_differences(const std::vector<const AntennaPhaseObservation*>& sats, int num_antennas,
                                          double phase_sigma_cycles, Include include) {
  std::vector<int> ref(static_cast<std::size_t>(num_antennas), -1);
  std::vector<std::vector<bool>> inc(static_cast<std::size_t>(num_antennas), std::vector<bool>(sats.size(), false));
  for (int k = 1; k < num_antennas; ++k) {
    double best = -10.0;
    for (std::size_t s = 0; s < sats.size(); ++s) {
      if (!include(s, k)) continue;
      inc[static_cast<std::size_t>(k)][s] = true;
      if (sats[s]->elevation_rad > best) {
        best = sats[s]->elevation_rad;
        ref[static_cast<std::size_t>(k)] = static_cast<int>(s);
      }
    }
  }
  return form_double_differences_with_references(sats, num_antennas, phase_sigma_cycles, ref, inc);
}

}  // namespace ultratrack::receiver

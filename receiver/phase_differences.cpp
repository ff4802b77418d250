// SPDX-License-Identifier: GPL-3.0-or-later
#include "receiver/phase_differences.hpp"

#include <array>

#include "signals/gps_constants.hpp"

namespace ultratrack::receiver {

Eigen::RowVector3d single_difference_geometry(const AntennaPhaseObservation& sat) {
  return -sat.los_e.transpose() / signals::kL1Wavelength_m;
}

DoubleDifferences form_double_differences_with_references(const std::vector<const AntennaPhaseObservation*>& sats,
                                                          int num_antennas, double phase_sigma_cycles,
                                                          const std::vector<int>& ref_sat,
                                                          const std::vector<std::vector<bool>>& included) {
  DoubleDifferences d;
  d.num_antennas = num_antennas;
  d.baseline_begin.assign(static_cast<std::size_t>(num_antennas), 0);
  d.baseline_count.assign(static_cast<std::size_t>(num_antennas), 0);
  for (int k = 1; k < num_antennas; ++k) {
    const auto ku = static_cast<std::size_t>(k);
    d.baseline_begin[ku] = static_cast<int>(d.rows.size());
    const int r = ref_sat[ku];
    if (r < 0) continue;
    for (std::size_t s = 0; s < sats.size(); ++s) {
      if (static_cast<int>(s) == r || !included[ku][s]) continue;
      d.rows.push_back({k, sats[s]->prn, sats[static_cast<std::size_t>(r)]->prn, s, static_cast<std::size_t>(r)});
    }
    d.baseline_count[ku] = static_cast<int>(d.rows.size()) - d.baseline_begin[ku];
  }
  const auto m = static_cast<Eigen::Index>(d.rows.size());
  d.dd_cycles.resize(m);
  d.geometry.resize(m, 3);
  // Each DD is +phi_k^s - phi_0^s - phi_k^r + phi_0^r: the covariance is sigma^2 times the overlap of these terms.
  struct Term {
    int antenna;
    std::size_t sat;
    double coef;
  };
  std::vector<std::array<Term, 4>> terms(d.rows.size());
  for (Eigen::Index i = 0; i < m; ++i) {
    const DdRow& row = d.rows[static_cast<std::size_t>(i)];
    const AntennaPhaseObservation& s = *sats[row.sat];
    const AntennaPhaseObservation& r = *sats[row.ref_sat];
    d.dd_cycles(i) = single_difference_cycles(s, row.antenna) - single_difference_cycles(r, row.antenna);
    d.geometry.row(i) = single_difference_geometry(s) - single_difference_geometry(r);
    terms[static_cast<std::size_t>(i)] = {Term{row.antenna, row.sat, 1.0}, Term{0, row.sat, -1.0},
                                          Term{row.antenna, row.ref_sat, -1.0}, Term{0, row.ref_sat, 1.0}};
  }
  d.covariance.setZero(m, m);
  const double var = phase_sigma_cycles * phase_sigma_cycles;
  for (Eigen::Index i = 0; i < m; ++i) {
    for (Eigen::Index j = i; j < m; ++j) {
      double c = 0.0;
      for (const Term& a : terms[static_cast<std::size_t>(i)]) {
        for (const Term& b : terms[static_cast<std::size_t>(j)]) {
          if (a.antenna == b.antenna && a.sat == b.sat) c += a.coef * b.coef;
        }
      }
      d.covariance(i, j) = d.covariance(j, i) = var * c;
    }
  }
  return d;
}

}  // namespace ultratrack::receiver

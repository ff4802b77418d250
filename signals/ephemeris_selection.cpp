// SPDX-License-Identifier: GPL-3.0-or-later
// Ephemeris selection: validity filters, then nearest toe (see the header for the tie rules).
#include "signals/ephemeris_selection.hpp"

#include <cmath>

#include "signals/rinex_nav.hpp"

namespace ultratrack::signals {

bool iode_matches_iodc(const Ephemeris& eph) { return (eph.iodc & 0xff) == eph.iode; }

bool within_fit_interval(const Ephemeris& eph, const GpsTime& t) {
  return std::abs(seconds_between(t, eph.toe())) <= 0.5 * fit_interval_hours(eph) * 3600.0;
}

std::optional<Ephemeris> select_ephemeris(const std::vector<Ephemeris>& sets, int prn, const GpsTime& t,
                                          const EphemerisSelectionOptions& options) {
  const Ephemeris* best = nullptr;
  double best_dt = 0.0;
  for (const Ephemeris& eph : sets) {
    if (eph.prn != prn) continue;
    if (eph.health != 0 && !options.include_unhealthy) continue;
    if (!iode_matches_iodc(eph) || !within_fit_interval(eph, t)) continue;
    const double dt = seconds_between(t, eph.toe());  // > 0: toe in the past
    bool better = best == nullptr || std::abs(dt) < std::abs(best_dt);
    if (best != nullptr && std::abs(dt) == std::abs(best_dt)) better = dt >= best_dt;  // past toe, later entry
    if (better) {
      best = &eph;
      best_dt = dt;
    }
  }
  if (best == nullptr) return std::nullopt;
  return *best;
}

}  // namespace ultratrack::signals

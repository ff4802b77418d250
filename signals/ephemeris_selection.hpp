// SPDX-License-Identifier: GPL-3.0-or-later
// Choosing the broadcast ephemeris to use for a satellite at a time, from all the sets received or read
// (IS-GPS-200 20.3.4.4): healthy, IODE equal to the low 8 bits of IODC, inside its curve-fit interval,
// and then the one whose toe is closest to the time.
#pragma once

#include <optional>
#include <vector>

#include "signals/ephemeris.hpp"
#include "signals/gps_time.hpp"

namespace ultratrack::signals {

struct EphemerisSelectionOptions {
  bool include_unhealthy = false;  // accept sets whose 6-bit SV health is not 0
};

// IODE equals the 8 least significant bits of IODC (IS-GPS-200 20.3.4.4); the two high IODC bits may be
// anything.
bool iode_matches_iodc(const Ephemeris& eph);

// |t - toe| <= half the curve-fit interval (fit_interval_hours in rinex_nav.hpp: 4 h for flag 0, so
// toe +- 2 h; 6 h or the IODC-table value for flag 1). toe sits at the centre of the fit interval.
bool within_fit_interval(const Ephemeris& eph, const GpsTime& t);

// The ephemeris for `prn` at `t`, or nothing when no set qualifies. Among qualifying sets the smallest
// |t - toe| wins; on a tie the set whose toe is not in the future wins, and among sets with the same toe
// the one later in `sets` (the later upload/reception) wins.
std::optional<Ephemeris> select_ephemeris(const std::vector<Ephemeris>& sets, int prn, const GpsTime& t,
                                          const EphemerisSelectionOptions& options = {});

}  // namespace ultratrack::signals

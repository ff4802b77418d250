// SPDX-License-Identifier: GPL-3.0-or-later
// A built-in GPS constellation so that simulations run without data files: the 24 slots of the GPS SPS
// Performance Standard's nominal constellation (6 planes A-F, 55 deg, A = 26559.7 km, near-circular) as
// broadcast ephemerides valid at a chosen time, with typical Klobuchar and UTC parameters. Deterministic.
#pragma once

#include <string>
#include <vector>

#include "signals/ephemeris.hpp"
#include "signals/gps_time.hpp"

namespace ultratrack::signals {

struct NominalConstellation {
  std::vector<Ephemeris> ephemerides;  // PRN 1..24 in slot order A1..A4, B1..B4, ..., F1..F4
  std::vector<std::string> slots;      // "A1", ... for each ephemeris
  KlobucharParameters klobuchar;
  UtcParameters utc;
};

// Ephemerides whose toe is the multiple of 2 h nearest to t (so t lies within +-1 h of toe, well inside
// the 4 h fit interval), week set, IODE == IODC, healthy, small clock terms.
NominalConstellation nominal_constellation(const GpsTime& t);

}  // namespace ultratrack::signals

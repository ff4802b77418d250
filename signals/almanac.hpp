// SPDX-License-Identifier: GPL-3.0-or-later
// The LNAV almanac of one satellite (subframe 4 pages 2-5, 7-10 and subframe 5 pages 1-24; IS-GPS-200
// 20.3.3.5.1.2, Table 20-VI) in SI units, and its orbit as a Keplerian Ephemeris (no harmonic corrections,
// no delta n) so that satellite_state() can place the satellite: kilometre-level positions for visibility
// and Doppler prediction, never for ranging. Angles in radians, times in seconds of the GPS week.
#pragma once

#include "signals/ephemeris.hpp"

namespace ultratrack::signals {

struct Almanac {
  int prn = 0;
  int week = 0;        // full week of toa (resolved against the time of transmission)
  double toa_s = 0.0;  // almanac reference time, seconds of week
  double e = 0.0;
  double i_rad = 0.0;  // 0.30 semicircles + delta i
  double omega_dot_radps = 0.0;
  double sqrt_a_sqrtm = 0.0;
  double omega0_rad = 0.0;
  double omega_rad = 0.0;
  double m0_rad = 0.0;
  double af0_s = 0.0;
  double af1_sps = 0.0;
  int health = 0;  // 8 bits: 3-bit NAV data health and 5-bit signal health (Tables 20-VII/VIII)
};

// The almanac as an ephemeris referenced to toa (toe = toc = toa), for satellite_state().
Ephemeris almanac_orbit(const Almanac& almanac);

}  // namespace ultratrack::signals

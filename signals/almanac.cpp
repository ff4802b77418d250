// SPDX-License-Identifier: GPL-3.0-or-later
#include "signals/almanac.hpp"

namespace ultratrack::signals {

Ephemeris almanac_orbit(const Almanac& a) {
  Ephemeris e;
  e.prn = a.prn;
  e.week = a.week;
  e.toe_s = a.toa_s;
  e.toc_s = a.toa_s;
  e.health = (a.health >> 5) != 0 ? 0x20 | (a.health & 0x1F) : (a.health & 0x1F);
  e.e = a.e;
  e.i0_rad = a.i_rad;
  e.omega_dot_radps = a.omega_dot_radps;
  e.sqrt_a_sqrtm = a.sqrt_a_sqrtm;
  e.omega0_rad = a.omega0_rad;
  e.omega_rad = a.omega_rad;
  e.m0_rad = a.m0_rad;
  e.af0_s = a.af0_s;
  e.af1_sps = a.af1_sps;
  return e;
}

}  // namespace ultratrack::signals

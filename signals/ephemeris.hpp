// SPDX-License-Identifier: GPL-3.0-or-later
// The broadcast ephemeris and clock parameters of one GPS satellite (LNAV subframes 1-3), in SI units:
// angles in radians (the broadcast semicircles are converted at the decoding/reading edge), rates in rad/s,
// times as seconds of the GPS week with their full week. IS-GPS-200 Tables 20-I/20-III.
#pragma once

#include "signals/gps_time.hpp"

namespace ultratrack::signals {

struct Ephemeris {
  int prn = 0;
  // Subframe 1: clock and health.
  int week = 0;        // full GPS week of toc/toe (rollover already resolved)
  int code_on_l2 = 1;  // 2-bit field
  int ura_index = 0;   // 4-bit URA index
  int health = 0;      // 6-bit SV health; 0 = all signals OK
  int iodc = 0;        // 10 bits
  int l2p_data_flag = 0;
  double tgd_s = 0.0;  // group delay differential, L1 C/A users subtract it
  double toc_s = 0.0;  // clock reference time, seconds of week
  double af0_s = 0.0;
  double af1_sps = 0.0;
  double af2_sps2 = 0.0;
  // Subframes 2-3: orbit.
  int iode = 0;        // 8 bits (subframes 2 and 3 both carry it)
  double toe_s = 0.0;  // ephemeris reference time, seconds of week
  double sqrt_a_sqrtm = 0.0;
  double e = 0.0;
  double m0_rad = 0.0;
  double delta_n_radps = 0.0;
  double omega0_rad = 0.0;  // longitude of ascending node at weekly epoch
  double i0_rad = 0.0;
  double omega_rad = 0.0;  // argument of perigee
  double omega_dot_radps = 0.0;
  double idot_radps = 0.0;
  double cuc_rad = 0.0, cus_rad = 0.0;
  double crc_m = 0.0, crs_m = 0.0;
  double cic_rad = 0.0, cis_rad = 0.0;
  int fit_interval_flag = 0;  // 0: 4 hours, 1: more than 4 hours
  int aodo = 0;               // subframe 2 age-of-data offset field (raw)

  GpsTime toe() const { return {week, toe_s}; }
  GpsTime toc() const { return {week, toc_s}; }
};

// Ionosphere (Klobuchar) parameters from subframe 4 page 18, in the broadcast units:
// alpha_n in s/semicircle^n, beta_n in s/semicircle^n (IS-GPS-200 20.3.3.5.1.7).
struct KlobucharParameters {
  double alpha[4] = {0, 0, 0, 0};
  double beta[4] = {0, 0, 0, 0};
  bool valid = false;
};

// UTC parameters from subframe 4 page 18 (IS-GPS-200 20.3.3.5.1.6).
struct UtcParameters {
  double a0_s = 0.0;
  double a1_sps = 0.0;
  int tot_s = 0;           // reference time of UTC data, seconds of week
  int wnt = 0;             // full week of tot
  int delta_t_ls_s = 18;   // current leap seconds
  int wn_lsf = 0;          // full week of the next leap second
  int dn = 0;              // day number (1-7) of the next leap second
  int delta_t_lsf_s = 18;  // leap seconds after it
  bool valid = false;
};

}  // namespace ultratrack::signals

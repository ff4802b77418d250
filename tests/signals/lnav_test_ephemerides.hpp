// SPDX-License-Identifier: GPL-3.0-or-later
// Broadcast ephemerides of 2022-01-01 00:00 GPST (week 2190, toe 518400 s) typed from the IGS file
// brdc0010.22n (RINEX 2.11 order), used as realistic inputs for the LNAV tests.
#pragma once

#include <array>
#include <vector>

#include "signals/ephemeris.hpp"

namespace ultratrack::test {

// RINEX 2 navigation record values, in file order after the epoch: af0 af1 af2 / IODE Crs dn M0 /
// Cuc e Cus sqrtA / toe Cic Omega0 Cis / i0 Crc omega Omegadot / IDOT codes week L2P / acc health TGD IODC.
inline signals::Ephemeris ephemeris_from_rinex(int prn, const std::array<double, 27>& v) {
  signals::Ephemeris e;
  e.prn = prn;
  e.af0_s = v[0], e.af1_sps = v[1], e.af2_sps2 = v[2];
  e.iode = static_cast<int>(v[3]), e.crs_m = v[4], e.delta_n_radps = v[5], e.m0_rad = v[6];
  e.cuc_rad = v[7], e.e = v[8], e.cus_rad = v[9], e.sqrt_a_sqrtm = v[10];
  e.toe_s = v[11], e.cic_rad = v[12], e.omega0_rad = v[13], e.cis_rad = v[14];
  e.i0_rad = v[15], e.crc_m = v[16], e.omega_rad = v[17], e.omega_dot_radps = v[18];
  e.idot_radps = v[19], e.code_on_l2 = static_cast<int>(v[20]), e.week = static_cast<int>(v[21]);
  e.l2p_data_flag = static_cast<int>(v[22]);
  e.ura_index = v[23] <= 2.4 ? 0 : 1;
  e.health = static_cast<int>(v[24]), e.tgd_s = v[25], e.iodc = static_cast<int>(v[26]);
  e.toc_s = 518400.0;
  return e;
}

inline std::vector<signals::Ephemeris> brdc_2022_001_ephemerides() {
  return {
      ephemeris_from_rinex(1, {0.469126738608e-03,
                               -0.100044417195e-10,
                               0.0,
                               39,
                               -141.125,
                               0.398838041777e-08,
                               -0.624294238235,
                               -0.736303627491e-05,
                               0.112181392033e-01,
                               0.469572842121e-05,
                               0.515367499542e+04,
                               518400,
                               -0.316649675369e-07,
                               -0.103661124009e+01,
                               0.195577740669e-06,
                               0.986418769490,
                               299.75,
                               0.884087601569,
                               -0.813355308085e-08,
                               -0.377872882780e-09,
                               1,
                               2190,
                               0,
                               2.0,
                               0,
                               0.512227416039e-08,
                               39}),
      ephemeris_from_rinex(2, {-0.647393986583e-03,
                               -0.113686837722e-11,
                               0.0,
                               41,
                               -142.71875,
                               0.455626121514e-08,
                               -0.453245129719,
                               -0.748783349991e-05,
                               0.206388905644e-01,
                               0.423192977905e-05,
                               0.515366817474e+04,
                               518400,
                               -0.258907675743e-06,
                               -0.112496293255e+01,
                               0.122934579849e-06,
                               0.964744088915,
                               303.625,
                               -0.146476911829e+01,
                               -0.868964767299e-08,
                               -0.262153776900e-09,
                               1,
                               2190,
                               0,
                               2.0,
                               0,
                               -0.176951289177e-07,
                               41}),
      ephemeris_from_rinex(4, {-0.196907203644e-03,
                               0.159161572810e-11,
                               0.0,
                               222,
                               14.53125,
                               0.494127725260e-08,
                               0.121899577520e+01,
                               0.813975930214e-06,
                               0.162550213281e-02,
                               0.561214983463e-05,
                               0.515365393639e+04,
                               518400,
                               0.130385160446e-07,
                               0.107951474039e+01,
                               0.130385160446e-07,
                               0.960658410342,
                               270.9375,
                               -0.312641513307e+01,
                               -0.814426781287e-08,
                               0.318227541169e-09,
                               1,
                               2190,
                               0,
                               2.0,
                               0,
                               -0.419095158577e-08,
                               990}),
      ephemeris_from_rinex(14, {-0.639976933598e-04,
                                -0.568434188608e-11,
                                0.0,
                                23,
                                144.96875,
                                0.439446876155e-08,
                                -0.193589100453e+01,
                                0.750459730625e-05,
                                0.126703013666e-02,
                                0.975653529167e-05,
                                0.515365150261e+04,
                                518400,
                                -0.186264514923e-08,
                                -0.310243739958e+01,
                                0.372529029846e-08,
                                0.954764367528,
                                190.53125,
                                0.306452368171e+01,
                                -0.788354266691e-08,
                                -0.242867259253e-10,
                                1,
                                2190,
                                0,
                                2.0,
                                0,
                                -0.791624188423e-08,
                                535}),
      ephemeris_from_rinex(18, {0.269385520369e-03,
                                -0.704858393874e-11,
                                0.0,
                                100,
                                -162.0,
                                0.419053169532e-08,
                                -0.429473514073,
                                -0.853836536408e-05,
                                0.209608941805e-02,
                                0.420212745667e-05,
                                0.515363635063e+04,
                                518400,
                                0.113621354103e-06,
                                -0.102811723490e+01,
                                -0.223517417908e-07,
                                0.970208257640,
                                305.0625,
                                0.309909716261e+01,
                                -0.813248160764e-08,
                                -0.400016662300e-09,
                                1,
                                2190,
                                0,
                                2.0,
                                0,
                                -0.838190317154e-08,
                                868}),
  };
}

// brdc0010.22n header: ION ALPHA / ION BETA / DELTA-UTC (A0, A1, tot, WNt) / LEAP SECONDS. The next leap
// second (week 2200, day 7, to 19 s) is made up: the file announces none, and WN_LSF must lie within
// 127 weeks of WN to survive its 8-bit broadcast.
inline signals::KlobucharParameters brdc_2022_001_klobuchar() {
  signals::KlobucharParameters k;
  const double alpha[4] = {0.1211e-07, -0.7451e-08, -0.5960e-07, 0.1192e-06};
  const double beta[4] = {0.1167e+06, -0.2458e+06, -0.6554e+05, 0.1114e+07};
  for (int i = 0; i < 4; ++i) k.alpha[i] = alpha[i], k.beta[i] = beta[i];
  k.valid = true;
  return k;
}

inline signals::UtcParameters brdc_2022_001_utc() {
  signals::UtcParameters u;
  u.a0_s = 0.279396772385e-08;
  u.a1_sps = 0.799360577730e-14;
  u.tot_s = 147456;
  u.wnt = 2191;
  u.delta_t_ls_s = 18;
  u.wn_lsf = 2200;
  u.dn = 7;
  u.delta_t_lsf_s = 19;
  u.valid = true;
  return u;
}

}  // namespace ultratrack::test

// SPDX-License-Identifier: GPL-3.0-or-later
// RINEX navigation reading (2.11 and 3.x, mixed files, malformed input) and the 3.04 writer (round trip).
#include "signals/rinex_nav.hpp"

#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <sstream>

#include "signals/input_error.hpp"
#include "support/test_data.hpp"

using namespace ultratrack::signals;

namespace {

// A RINEX 3.04 mixed file written by hand from the format tables: a Galileo record (7 lines), a GLONASS
// record (3 lines), a GPS record with a short last line, an SBAS record, and blank lines.
const char* kMixed304 =
    "     3.04           N: GNSS NAV DATA    M: MIXED            RINEX VERSION / TYPE\n"
    "hand written                            20220102 000000 UTC PGM / RUN BY / DATE\n"
    "GAL    2.9750E+01  3.4375E-01  1.1902E-02  0.0000E+00       IONOSPHERIC CORR\n"
    "GPSA   1.2107E-08 -7.4506E-09 -5.9605E-08  1.1921E-07       IONOSPHERIC CORR\n"
    "GPSB   1.1674E+05 -2.4576E+05 -6.5536E+04  1.1141E+06       IONOSPHERIC CORR\n"
    "GAUT  9.3132257462E-10-8.881784197E-16 345600 2190          TIME SYSTEM CORR\n"
    "GPUT  2.7939677239E-09 7.993605777E-15 147456 2191          TIME SYSTEM CORR\n"
    "    18    18  2185     7                                    LEAP SECONDS\n"
    "                                                            END OF HEADER\n"
    "E01 2022 01 01 00 00 00-6.514282524586E-04-7.943690490304E-12 0.000000000000E+00\n"
    "     6.300000000000E+01 1.750000000000E+01 2.800116636387E-09-2.046004295626E+00\n"
    "     8.819252252579E-07 1.659416779876E-04 1.144781708717E-05 5.440629440308E+03\n"
    "     5.184000000000E+05 9.313225746155E-09 3.048017233005E-01-3.539025783539E-08\n"
    "     9.885453286406E-01 1.095312500000E+02-5.589286004497E-01-5.505586749380E-09\n"
    "    -1.914365448680E-10 5.170000000000E+02 2.190000000000E+03\n"
    "     3.120000000000E+00 0.000000000000E+00 2.793967723846E-09 3.259629011154E-09\n"
    "     5.191050000000E+05\n"
    "\n"
    "R01 2022 01 01 00 15 00 7.662735879421E-06-0.000000000000E+00 5.184000000000E+05\n"
    "     2.357104101562E+04-7.162170410156E-01 1.862645149231E-09 0.000000000000E+00\n"
    "    -3.887426757812E+03 4.008770942688E-01 2.793967723846E-09 1.000000000000E+00\n"
    "    -6.102031738281E+03-3.506383895874E+00 0.000000000000E+00 0.000000000000E+00\n"
    "G05 2022 01 01 02 00 00-2.586906775832E-05-4.888534022029E-12 0.000000000000E+00\n"
    "     5.400000000000E+01 3.125000000000E+01 4.517690474355E-09-3.120281450818E+00\n"
    "     1.587718725204E-06 5.822420492768E-03 9.916350245476E-06 5.153644044876E+03\n"
    "     5.256000000000E+05-2.048909664154E-08 2.102478076066E+00-1.322478055954E-07\n"
    "     9.585626924216E-01 1.956875000000E+02 6.812305689543E-01-8.056050174046E-09\n"
    "    -6.153827668773E-10 1.000000000000E+00 2.190000000000E+03 0.000000000000E+00\n"
    "     2.000000000000E+00 0.000000000000E+00-1.024454832077E-08 5.400000000000E+01\n"
    "     5.184180000000E+05\n"
    "S23 2022 01 01 00 01 04 0.000000000000E+00 0.000000000000E+00 5.184640000000E+05\n"
    "     3.704932560000E+07 0.000000000000E+00 0.000000000000E+00 6.300000000000E+01\n"
    "    -4.114164800000E+06 0.000000000000E+00 0.000000000000E+00 4.096000000000E+03\n"
    "     2.260800000000E+04 0.000000000000E+00 0.000000000000E+00 0.000000000000E+00\n"
    "\n";

RinexNavData parse(const std::string& text) {
  std::istringstream in(text);
  return read_rinex_nav(in, "test.rnx");
}

// Expects InputError whose message names the file and the given line and contains `what`.
void expect_error_at(const std::string& text, int line, const std::string& what) {
  try {
    parse(text);
    ADD_FAILURE() << "no error for: " << what;
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), "test.rnx");
    EXPECT_EQ(e.line(), line) << e.what();
    EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    const std::string where = line > 0 ? "test.rnx:" + std::to_string(line) + ":" : "test.rnx:";
    EXPECT_EQ(std::string(e.what()).rfind(where, 0), 0u) << e.what();
  }
}

std::string replace_line(std::string text, int line_no, const std::string& replacement) {
  std::istringstream in(text);
  std::string out, line;
  for (int n = 1; std::getline(in, line); ++n) out += (n == line_no ? replacement : line) + "\n";
  return out;
}

std::string first_lines(const std::string& text, int count) {
  std::istringstream in(text);
  std::string out, line;
  for (int n = 0; n < count && std::getline(in, line); ++n) out += line + "\n";
  return out;
}

}  // namespace

TEST(RinexNav, ReadsMixed304KeepingGpsAndSkippingOtherSystems) {
  const RinexNavData nav = parse(kMixed304);
  ASSERT_EQ(nav.ephemerides.size(), 1u);
  const Ephemeris& e = nav.ephemerides[0];
  EXPECT_EQ(e.prn, 5);
  EXPECT_EQ(e.week, 2190);
  EXPECT_DOUBLE_EQ(e.toc_s, 525600.0);  // 2022-01-01 02:00:00 = 518400 + 7200
  EXPECT_DOUBLE_EQ(e.toe_s, 525600.0);
  EXPECT_DOUBLE_EQ(e.af0_s, -2.586906775832e-05);
  EXPECT_DOUBLE_EQ(e.af1_sps, -4.888534022029e-12);
  EXPECT_EQ(e.iode, 54);
  EXPECT_EQ(e.iodc, 54);
  EXPECT_DOUBLE_EQ(e.sqrt_a_sqrtm, 5.153644044876e+03);
  EXPECT_DOUBLE_EQ(e.omega_dot_radps, -8.056050174046e-09);
  EXPECT_DOUBLE_EQ(e.tgd_s, -1.024454832077e-08);
  EXPECT_EQ(e.ura_index, 0);          // 2.0 m
  EXPECT_EQ(e.fit_interval_flag, 0);  // missing fit interval reads as 0 (= 4 h)
  EXPECT_DOUBLE_EQ(nav.transmit_tow_s[0], 518418.0);
  EXPECT_TRUE(nav.klobuchar.valid);
  EXPECT_DOUBLE_EQ(nav.klobuchar.alpha[1], -7.4506e-09);
  EXPECT_DOUBLE_EQ(nav.klobuchar.beta[3], 1.1141e+06);
  ASSERT_TRUE(nav.utc.valid);
  EXPECT_DOUBLE_EQ(nav.utc.a0_s, 2.7939677239e-09);  // GPUT, not GAUT
  EXPECT_DOUBLE_EQ(nav.utc.a1_sps, 7.993605777e-15);
  EXPECT_EQ(nav.utc.tot_s, 147456);
  EXPECT_EQ(nav.utc.wnt, 2191);
  EXPECT_EQ(nav.utc.delta_t_ls_s, 18);
  EXPECT_EQ(nav.utc.delta_t_lsf_s, 18);
  EXPECT_EQ(nav.utc.wn_lsf, 2185);
  EXPECT_EQ(nav.utc.dn, 7);
}

TEST(RinexNav, Reads305WithFourLineGlonassRecords) {
  std::string text =
      replace_line(kMixed304, 1, "     3.05           N: GNSS NAV DATA    M: MIXED            RINEX VERSION / TYPE");
  // Insert the fourth GLONASS line (3.05) after line 22.
  std::istringstream in(text);
  std::string out, line;
  for (int n = 1; std::getline(in, line); ++n) {
    out += line + "\n";
    if (n == 22) out += "     1.790000000000E+02 0.000000000000E+00 2.000000000000E+00 0.000000000000E+00\n";
  }
  const RinexNavData nav = parse(out);
  ASSERT_EQ(nav.ephemerides.size(), 1u);
  EXPECT_EQ(nav.ephemerides[0].prn, 5);
}

TEST(RinexNav, Reads211WithDExponentsTwoDigitYearsAndShortLines) {
  const std::string text =
      "     2.11           N: GPS NAV DATA                         RINEX VERSION / TYPE\n"
      "    0.1211D-07 -0.7451D-08 -0.5960D-07  0.1192D-06          ION ALPHA\n"
      "    0.1167D+06 -0.2458D+06 -0.6554D+05  0.1114D+07          ION BETA\n"
      "    0.279396772385D-08 0.799360577730D-14   147456     2191 DELTA-UTC: A0,A1,T,W\n"
      "    18                                                      LEAP SECONDS\n"
      "                                                            END OF HEADER\n"
      "\n"
      "14 99 12 31 22  0  0.0-0.639976933598D-04-0.568434188608D-11 0.000000000000D+00\n"
      "    0.230000000000D+02 0.144968750000D+03 0.439446876155D-08-0.193589100453D+01\n"
      "    0.750459730625D-05 0.126703013666D-02 0.975653529167D-05 0.515365150261D+04\n"
      "    0.511200000000D+06-0.186264514923D-08-0.310243739958D+01 0.372529029846D-08\n"
      "    0.954764367528D+00 0.190531250000D+03 0.306452368171D+01-0.788354266691D-08\n"
      "   -0.242867259253D-10 0.100000000000D+01 0.104200000000D+04 0.000000000000D+00\n"
      "    0.200000000000D+01 0.000000000000D+00-0.791624188423D-08 0.535000000000D+03\n"
      "    0.515646000000D+06 0.600000000000D+01\n";
  const RinexNavData nav = parse(text);
  ASSERT_EQ(nav.ephemerides.size(), 1u);
  const Ephemeris& e = nav.ephemerides[0];
  EXPECT_EQ(e.prn, 14);
  EXPECT_EQ(e.week, 1042);              // 1999-12-31 is the Friday of GPS week 1042 (1024 + 18)
  EXPECT_DOUBLE_EQ(e.toc_s, 511200.0);  // 5 days + 22 h
  EXPECT_DOUBLE_EQ(e.m0_rad, -0.193589100453e+01);
  EXPECT_EQ(e.iode, 23);
  EXPECT_EQ(e.iodc, 535);
  EXPECT_EQ(e.fit_interval_flag, 1);  // 6 hours
  EXPECT_NEAR(nav.klobuchar.alpha[0], 0.1211e-07, 1e-22);
  EXPECT_NEAR(nav.klobuchar.beta[2], -0.6554e+05, 1e-9);
  EXPECT_EQ(nav.utc.wnt, 2191);
  EXPECT_TRUE(nav.has_leap_seconds);
  EXPECT_EQ(nav.utc.delta_t_ls_s, 18);
}

// The broadcast ephemeris shipped with the tests (tests/data/README.md): a RINEX 2 file as CDDIS merged it,
// header and the records of 00:00-02:00, checked field by field against the file text.
TEST(RinexNav, ReadsShippedBrdc3540) {
  const RinexNavData nav = read_rinex_nav(ultratrack::test::shipped_nav_file());
  EXPECT_NEAR(nav.version, 2.0, 1e-12);
  EXPECT_EQ(nav.ephemerides.size(), 68u);  // (552 - 8 header lines) / 8
  const Ephemeris& e = nav.ephemerides.at(0);
  EXPECT_EQ(e.prn, 1);
  EXPECT_EQ(e.week, 1823);
  EXPECT_DOUBLE_EQ(e.toc_s, 518400.0);
  EXPECT_DOUBLE_EQ(e.af0_s, -0.109937973321e-04);
  EXPECT_DOUBLE_EQ(e.af1_sps, 0.341060513165e-12);
  EXPECT_DOUBLE_EQ(e.af2_sps2, 0.0);
  EXPECT_EQ(e.iode, 92);
  EXPECT_DOUBLE_EQ(e.crs_m, 0.183125000000e+02);
  EXPECT_DOUBLE_EQ(e.delta_n_radps, 0.486413118202e-08);
  EXPECT_DOUBLE_EQ(e.m0_rad, 0.206468198931e+01);
  EXPECT_DOUBLE_EQ(e.cuc_rad, 0.944361090660e-06);
  EXPECT_DOUBLE_EQ(e.e, 0.373082933947e-02);
  EXPECT_DOUBLE_EQ(e.cus_rad, 0.576488673687e-05);
  EXPECT_DOUBLE_EQ(e.sqrt_a_sqrtm, 0.515366174698e+04);
  EXPECT_DOUBLE_EQ(e.toe_s, 518400.0);
  EXPECT_DOUBLE_EQ(e.cic_rad, -0.540167093277e-07);
  EXPECT_DOUBLE_EQ(e.omega0_rad, 0.952167249062e+00);
  EXPECT_DOUBLE_EQ(e.cis_rad, 0.204890966415e-07);
  EXPECT_DOUBLE_EQ(e.i0_rad, 0.961377027886e+00);
  EXPECT_DOUBLE_EQ(e.crc_m, 0.266968750000e+03);
  EXPECT_DOUBLE_EQ(e.omega_rad, 0.444935335171e+00);
  EXPECT_DOUBLE_EQ(e.omega_dot_radps, -0.814641075928e-08);
  EXPECT_DOUBLE_EQ(e.idot_radps, 0.415017287136e-09);
  EXPECT_EQ(e.code_on_l2, 1);
  EXPECT_EQ(e.l2p_data_flag, 0);
  EXPECT_EQ(e.ura_index, 0);  // 2.0 m
  EXPECT_EQ(e.health, 0);
  EXPECT_DOUBLE_EQ(e.tgd_s, 0.558793544769e-08);
  EXPECT_EQ(e.iodc, 92);
  EXPECT_DOUBLE_EQ(nav.transmit_tow_s.at(0), 511218.0);
  EXPECT_EQ(e.fit_interval_flag, 0);  // 4 hours
  // Header: ION ALPHA / ION BETA / DELTA-UTC / LEAP SECONDS (16 s in 2014).
  EXPECT_TRUE(nav.klobuchar.valid);
  EXPECT_DOUBLE_EQ(nav.klobuchar.alpha[0], 0.2887e-07);
  EXPECT_DOUBLE_EQ(nav.klobuchar.alpha[2], -0.1192e-06);
  EXPECT_DOUBLE_EQ(nav.klobuchar.beta[1], -0.1966e+06);
  EXPECT_DOUBLE_EQ(nav.klobuchar.beta[3], 0.3932e+06);
  EXPECT_DOUBLE_EQ(nav.utc.a0_s, 0.186264514923e-08);
  EXPECT_DOUBLE_EQ(nav.utc.a1_sps, 0.799360577730e-14);
  EXPECT_EQ(nav.utc.tot_s, 61440);
  EXPECT_EQ(nav.utc.wnt, 1824);
  EXPECT_TRUE(nav.has_leap_seconds);
  EXPECT_EQ(nav.utc.delta_t_ls_s, 16);
  // The last record (PRN 32 at 02:00), the 01:59:44 set of PRN 22, and PRN 8: unhealthy in every record.
  EXPECT_EQ(nav.ephemerides.back().prn, 32);
  EXPECT_DOUBLE_EQ(nav.ephemerides.back().toe_s, 525600.0);
  EXPECT_DOUBLE_EQ(nav.transmit_tow_s.back(), 518418.0);
  int sets22 = 0, sets8 = 0;
  for (const Ephemeris& x : nav.ephemerides) {
    EXPECT_EQ(x.week, 1823);
    if (x.prn == 22 && x.toe_s == 525584.0) {
      ++sets22;
      EXPECT_EQ(x.iode, 6);
      EXPECT_DOUBLE_EQ(x.toc_s, 525584.0);
    }
    if (x.prn == 8) {
      ++sets8;
      EXPECT_EQ(x.health, 63);
    }
  }
  EXPECT_EQ(sets22, 1);
  EXPECT_EQ(sets8, 2);
}

TEST(RinexNav, WriteThenReadGivesTheSameValues) {
  const RinexNavData in = read_rinex_nav(ultratrack::test::shipped_nav_file());
  const auto out_path = ultratrack::test::scratch_dir() / "out.rnx";
  write_rinex_nav_304(out_path, in);
  EXPECT_FALSE(std::filesystem::exists(out_path.string() + ".tmp"));
  const RinexNavData back = read_rinex_nav(out_path);
  EXPECT_NEAR(back.version, 3.04, 1e-12);
  ASSERT_EQ(back.ephemerides.size(), in.ephemerides.size());
  // %19.12E keeps 13 significant digits: relative agreement 5e-13.
  const auto near = [](double a, double b) { return std::abs(a - b) <= 5e-13 * std::abs(b) + 1e-300; };
  for (size_t i = 0; i < in.ephemerides.size(); ++i) {
    const Ephemeris& a = in.ephemerides[i];
    const Ephemeris& b = back.ephemerides[i];
    EXPECT_EQ(a.prn, b.prn);
    EXPECT_EQ(a.week, b.week);
    EXPECT_EQ(a.iode, b.iode);
    EXPECT_EQ(a.iodc, b.iodc);
    EXPECT_EQ(a.health, b.health);
    EXPECT_EQ(a.ura_index, b.ura_index);
    EXPECT_EQ(a.code_on_l2, b.code_on_l2);
    EXPECT_EQ(a.l2p_data_flag, b.l2p_data_flag);
    EXPECT_EQ(a.fit_interval_flag, b.fit_interval_flag);
    EXPECT_DOUBLE_EQ(a.toc_s, b.toc_s);
    for (auto [x, y] : {std::pair{a.af0_s, b.af0_s},
                        {a.af1_sps, b.af1_sps},
                        {a.af2_sps2, b.af2_sps2},
                        {a.tgd_s, b.tgd_s},
                        {a.toe_s, b.toe_s},
                        {a.sqrt_a_sqrtm, b.sqrt_a_sqrtm},
                        {a.e, b.e},
                        {a.m0_rad, b.m0_rad},
                        {a.delta_n_radps, b.delta_n_radps},
                        {a.omega0_rad, b.omega0_rad},
                        {a.i0_rad, b.i0_rad},
                        {a.omega_rad, b.omega_rad},
                        {a.omega_dot_radps, b.omega_dot_radps},
                        {a.idot_radps, b.idot_radps},
                        {a.cuc_rad, b.cuc_rad},
                        {a.cus_rad, b.cus_rad},
                        {a.crc_m, b.crc_m},
                        {a.crs_m, b.crs_m},
                        {a.cic_rad, b.cic_rad},
                        {a.cis_rad, b.cis_rad},
                        {in.transmit_tow_s[i], back.transmit_tow_s[i]}})
      EXPECT_TRUE(near(x, y)) << "record " << i << ": " << x << " vs " << y;
  }
  EXPECT_TRUE(back.klobuchar.valid);
  for (int k = 0; k < 4; ++k) {
    EXPECT_NEAR(back.klobuchar.alpha[k], in.klobuchar.alpha[k], 5e-5 * std::abs(in.klobuchar.alpha[k]));
    EXPECT_NEAR(back.klobuchar.beta[k], in.klobuchar.beta[k], 5e-5 * std::abs(in.klobuchar.beta[k]));
  }
  EXPECT_NEAR(back.utc.a0_s, in.utc.a0_s, 1e-10 * std::abs(in.utc.a0_s));
  EXPECT_NEAR(back.utc.a1_sps, in.utc.a1_sps, 1e-9 * std::abs(in.utc.a1_sps));
  EXPECT_EQ(back.utc.tot_s, in.utc.tot_s);
  EXPECT_EQ(back.utc.wnt, in.utc.wnt);
  EXPECT_EQ(back.utc.delta_t_ls_s, 16);  // the file's (not the default 18)
}

TEST(RinexNav, RoundTripsExtendedFitIntervalAndUraIndices) {
  RinexNavData d;
  for (int k = 0; k < 16; ++k) {
    Ephemeris e;
    e.prn = k + 1;
    e.week = 2300;
    e.toe_s = e.toc_s = 7200.0 * k;
    e.sqrt_a_sqrtm = 5153.7;
    e.e = 0.01;
    e.ura_index = k;
    e.iodc = 240 + k;
    e.iode = e.iodc & 0xff;
    e.fit_interval_flag = k % 2;
    d.ephemerides.push_back(e);
  }
  const auto p = ultratrack::test::scratch_dir() / "fit.rnx";
  write_rinex_nav_304(p, d);
  const RinexNavData back = read_rinex_nav(p);
  ASSERT_EQ(back.ephemerides.size(), 16u);
  for (int k = 0; k < 16; ++k) {
    EXPECT_EQ(back.ephemerides[k].ura_index, k);
    EXPECT_EQ(back.ephemerides[k].fit_interval_flag, k % 2);
    EXPECT_DOUBLE_EQ(back.transmit_tow_s[k], 7200.0 * k);  // unknown transmission time written as toe
  }
  EXPECT_FALSE(back.klobuchar.valid);
  EXPECT_FALSE(back.utc.valid);
}

TEST(RinexNav, MalformedInputNamesFileLineAndProblem) {
  expect_error_at("", 0, "empty file");
  expect_error_at("garbage\n", 1, "RINEX VERSION / TYPE");
  expect_error_at(
      replace_line(kMixed304, 1, "     4.00           N: GNSS NAV DATA    M: MIXED            RINEX VERSION / TYPE"), 1,
      "unsupported RINEX version");
  expect_error_at(
      replace_line(kMixed304, 1, "     3.04           O: OBSERVATION DATA M: MIXED            RINEX VERSION / TYPE"), 1,
      "wrong file type");
  expect_error_at(
      replace_line(kMixed304, 1, "     3.04           N: GNSS NAV DATA    E: GALILEO          RINEX VERSION / TYPE"), 1,
      "only GPS");
  expect_error_at(first_lines(kMixed304, 5), 5, "END OF HEADER");
  // An unparseable number in the GPS record (line 24 = first orbit line of G05).
  expect_error_at(
      replace_line(kMixed304, 24, "     5.400000000000E+01 3.12500x000000E+01 4.517690474355E-09-3.120281450818E+00"),
      24, "cannot parse");
  // A GPS record cut after three orbit lines, followed by the next record.
  {
    std::istringstream in(kMixed304);
    std::string out, line;
    for (int n = 1; std::getline(in, line); ++n)
      if (n < 27 || n > 30) out += line + "\n";
    expect_error_at(out, 27, "truncated record for G05");
  }
  // The file ends inside the GPS record.
  expect_error_at(first_lines(kMixed304, 26), 26, "truncated record for G05");
  // The file ends inside the Galileo record.
  expect_error_at(first_lines(kMixed304, 13), 13, "truncated record for system 'E'");
  // Nonsense orbit (sqrt(A) = 0) is rejected with the record's line.
  expect_error_at(
      replace_line(kMixed304, 25, "     1.587718725204E-06 5.822420492768E-03 9.916350245476E-06 0.000000000000E+00"),
      23, "sqrt(A)");
  // A week of 2^32 + 2190: range-checked as written, not wrapped to 2190 by the conversion to int.
  expect_error_at(
      replace_line(kMixed304, 28, "    -6.153827668773E-10 1.000000000000E+00 4.294969486000E+09 0.000000000000E+00"),
      23, "GPS week 4294969486 out of range");
  // A NaN-free but absurd IODC, and a health word beyond its 6 bits.
  expect_error_at(
      replace_line(kMixed304, 29, "     2.000000000000E+00 0.000000000000E+00-1.024454832077E-08 1.000000000000E+30"),
      23, "IODC 1e+30 out of range");
  expect_error_at(
      replace_line(kMixed304, 29, "     2.000000000000E+00 6.400000000000E+01-1.024454832077E-08 5.400000000000E+01"),
      23, "SV health 64 out of range");
}

TEST(RinexNav, MissingFileThrowsInputErrorNamingIt) {
  const auto p = ultratrack::test::scratch_dir() / "no_such.rnx";
  try {
    read_rinex_nav(p);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), p.string());
    EXPECT_NE(std::string(e.what()).find("cannot open"), std::string::npos);
  }
}

// RTKLIB (an independent RINEX implementation) must read what we write: when its convbin is installed,
// our 3.04 file goes through convbin (RINEX 3.04 in, RINEX 3.04 out) and the result is read back.
TEST(RinexNav, RtklibConvbinReadsOurFile) {
  if (std::system("command -v convbin >/dev/null 2>&1") != 0) GTEST_SKIP() << "RTKLIB convbin not installed";
  const RinexNavData in = read_rinex_nav(ultratrack::test::shipped_nav_file());
  const auto dir = ultratrack::test::scratch_dir();
  write_rinex_nav_304(dir / "ours.rnx", in);
  const std::string cmd =
      "cd '" + dir.string() + "' && convbin -r rinex -v 3.04 -n rtklib.rnx ours.rnx >/dev/null 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0);
  const RinexNavData back = read_rinex_nav(dir / "rtklib.rnx");
  ASSERT_EQ(back.ephemerides.size(), in.ephemerides.size());
  // RTKLIB sorts by PRN and time: match records by (PRN, toe, IODE) and compare to the printed precision.
  for (const Ephemeris& a : in.ephemerides) {
    const Ephemeris* b = nullptr;
    for (const Ephemeris& x : back.ephemerides)
      if (x.prn == a.prn && x.toe_s == a.toe_s && x.iode == a.iode && x.iodc == a.iodc) b = &x;
    ASSERT_NE(b, nullptr) << "PRN " << a.prn << " toe " << a.toe_s;
    EXPECT_EQ(b->week, a.week);
    EXPECT_EQ(b->health, a.health);
    EXPECT_DOUBLE_EQ(b->toc_s, a.toc_s);
    EXPECT_NEAR(b->af0_s, a.af0_s, 5e-13 * std::abs(a.af0_s));
    EXPECT_NEAR(b->m0_rad, a.m0_rad, 5e-13 * std::abs(a.m0_rad));
    EXPECT_NEAR(b->sqrt_a_sqrtm, a.sqrt_a_sqrtm, 5e-13 * a.sqrt_a_sqrtm);
    EXPECT_NEAR(b->omega0_rad, a.omega0_rad, 5e-13 * std::abs(a.omega0_rad));
    EXPECT_NEAR(b->tgd_s, a.tgd_s, 5e-13 * std::abs(a.tgd_s) + 1e-30);
  }
}

TEST(RinexNav, WriterReportsUnwritablePathAndBadRecords) {
  RinexNavData d;
  const auto dir = ultratrack::test::scratch_dir();
  EXPECT_THROW(write_rinex_nav_304(dir / "no_such_dir" / "x.rnx", d), InputError);
  Ephemeris bad;
  bad.prn = 40;
  d.ephemerides.push_back(bad);
  EXPECT_THROW(write_rinex_nav_304(dir / "x.rnx", d), InputError);
  EXPECT_FALSE(std::filesystem::exists(dir / "x.rnx"));
}

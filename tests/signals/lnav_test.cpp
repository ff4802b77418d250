// SPDX-License-Identifier: GPL-3.0-or-later
// LNAV message: transmitter -> bits -> decoder round trips on real broadcast ephemerides, field positions
// read straight from the transmitted bits with IS-GPS-200's bit numbers, parity error detection, polarity,
// HOW timing, frames entered mid-way, and the bit stream on the air across subframe and week boundaries.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <set>

#include "lnav_test_ephemerides.hpp"
#include "signals/gps_constants.hpp"
#include "signals/input_error.hpp"
#include "signals/lnav_decoder.hpp"
#include "signals/lnav_transmitter.hpp"
#include "signals/satellite_state.hpp"

using namespace ultratrack::signals;
using ultratrack::test::brdc_2022_001_ephemerides;
using ultratrack::test::brdc_2022_001_klobuchar;
using ultratrack::test::brdc_2022_001_utc;

namespace {

constexpr int kWeek = 2190;
constexpr double kToe = 518400.0;  // Saturday 00:00, start of a frame (518400 / 30 is whole)

LnavTransmitter make_transmitter(const Ephemeris& e) {
  return LnavTransmitter(e, brdc_2022_001_klobuchar(), brdc_2022_001_utc(), brdc_2022_001_ephemerides());
}

// Reads data bit n (1-based subframe bit number) as IS-GPS-200 defines it: the transmitted bit
// complemented when the previous word's last bit D30* is 1 (the subframe itself starts after a 0).
int data_bit(const SubframeBits& bits, int n) {
  const int word = (n - 1) / 30;
  const int prev_d30 = word == 0 ? 0 : bits[static_cast<std::size_t>(30 * word - 1)];
  return bits[static_cast<std::size_t>(n - 1)] ^ prev_d30;
}
std::uint32_t raw_field(const SubframeBits& bits, int first, int length) {
  std::uint32_t v = 0;
  for (int n = first; n < first + length; ++n) v = (v << 1) | static_cast<std::uint32_t>(data_bit(bits, n));
  return v;
}
std::int64_t signed_field(const SubframeBits& bits, int first, int length) {
  const std::int64_t v = raw_field(bits, first, length);
  return v >= (std::int64_t{1} << (length - 1)) ? v - (std::int64_t{1} << length) : v;
}

// |decoded - original| <= LSB/2, plus a few ulps for the double arithmetic of the scaling.
void expect_within_half_lsb(double decoded, double original, double lsb, const char* what, int prn) {
  const double tol = 0.5 * lsb + 4.0 * std::numeric_limits<double>::epsilon() * std::abs(original);
  EXPECT_LE(std::abs(decoded - original), tol) << what << " PRN " << prn << ": " << decoded << " vs " << original;
}

// Feeds the subframes starting at `start` for n subframes, each with the real previous two bits.
void feed(LnavDecoder& decoder, const LnavTransmitter& tx, GpsTime start, int n) {
  std::array<std::uint8_t, 2> prev{0, 0};
  for (int k = 0; k < n; ++k) {
    const SubframeBits bits = tx.subframe_starting_at(add_seconds(start, 6.0 * k));
    ASSERT_EQ(decoder.add_bits(bits, prev), LnavStatus::kOk) << "subframe " << k;
    prev = {bits[298], bits[299]};
  }
}

}  // namespace

TEST(LnavRoundTrip, EveryEphemerisFieldWithinHalfLsb) {
  for (const Ephemeris& e : brdc_2022_001_ephemerides()) {
    LnavDecoder decoder(e.prn, kWeek + 300);  // reference week off by 300: WN mod 1024 still resolves
    feed(decoder, make_transmitter(e), {kWeek, kToe}, 5);
    ASSERT_TRUE(decoder.ephemeris().has_value()) << e.prn;
    const Ephemeris& d = *decoder.ephemeris();
    const int prn = e.prn;
    EXPECT_EQ(d.prn, prn);
    EXPECT_EQ(d.week, kWeek);
    EXPECT_EQ(d.iode, e.iode);
    EXPECT_EQ(d.iodc, e.iodc);  // PRN 4, 14, 18: IODC != IODE, low 8 bits equal
    EXPECT_EQ(d.code_on_l2, e.code_on_l2);
    EXPECT_EQ(d.ura_index, e.ura_index);
    EXPECT_EQ(d.health, e.health);
    EXPECT_EQ(d.l2p_data_flag, e.l2p_data_flag);
    EXPECT_EQ(d.fit_interval_flag, e.fit_interval_flag);
    EXPECT_EQ(d.aodo, e.aodo);
    // Scale factors of IS-GPS-200 Tables 20-I and 20-III; semicircles are converted with kPi.
    expect_within_half_lsb(d.tgd_s, e.tgd_s, std::ldexp(1.0, -31), "TGD", prn);
    expect_within_half_lsb(d.toc_s, e.toc_s, 16.0, "toc", prn);
    expect_within_half_lsb(d.af2_sps2, e.af2_sps2, std::ldexp(1.0, -55), "af2", prn);
    expect_within_half_lsb(d.af1_sps, e.af1_sps, std::ldexp(1.0, -43), "af1", prn);
    expect_within_half_lsb(d.af0_s, e.af0_s, std::ldexp(1.0, -31), "af0", prn);
    expect_within_half_lsb(d.crs_m, e.crs_m, std::ldexp(1.0, -5), "Crs", prn);
    expect_within_half_lsb(d.delta_n_radps, e.delta_n_radps, std::ldexp(kPi, -43), "delta n", prn);
    expect_within_half_lsb(d.m0_rad, e.m0_rad, std::ldexp(kPi, -31), "M0", prn);
    expect_within_half_lsb(d.cuc_rad, e.cuc_rad, std::ldexp(1.0, -29), "Cuc", prn);
    expect_within_half_lsb(d.e, e.e, std::ldexp(1.0, -33), "e", prn);
    expect_within_half_lsb(d.cus_rad, e.cus_rad, std::ldexp(1.0, -29), "Cus", prn);
    expect_within_half_lsb(d.sqrt_a_sqrtm, e.sqrt_a_sqrtm, std::ldexp(1.0, -19), "sqrt A", prn);
    expect_within_half_lsb(d.toe_s, e.toe_s, 16.0, "toe", prn);
    expect_within_half_lsb(d.cic_rad, e.cic_rad, std::ldexp(1.0, -29), "Cic", prn);
    expect_within_half_lsb(d.omega0_rad, e.omega0_rad, std::ldexp(kPi, -31), "Omega0", prn);
    expect_within_half_lsb(d.cis_rad, e.cis_rad, std::ldexp(1.0, -29), "Cis", prn);
    expect_within_half_lsb(d.i0_rad, e.i0_rad, std::ldexp(kPi, -31), "i0", prn);
    expect_within_half_lsb(d.crc_m, e.crc_m, std::ldexp(1.0, -5), "Crc", prn);
    expect_within_half_lsb(d.omega_rad, e.omega_rad, std::ldexp(kPi, -31), "omega", prn);
    expect_within_half_lsb(d.omega_dot_radps, e.omega_dot_radps, std::ldexp(kPi, -43), "Omega dot", prn);
    expect_within_half_lsb(d.idot_radps, e.idot_radps, std::ldexp(kPi, -43), "IDOT", prn);
    EXPECT_EQ(decoder.counters().parity_errors, 0);
  }
}

TEST(LnavRoundTrip, KlobucharAndUtcWithinHalfLsb) {
  const Ephemeris e = brdc_2022_001_ephemerides()[0];
  LnavDecoder decoder(e.prn, kWeek);
  // Subframe 4 page 18 is transmitted in the frame starting at 17 x 30 s after a 750 s cycle start.
  const double frame18 = std::floor(kToe / 750.0) * 750.0 + 17 * 30.0;
  feed(decoder, make_transmitter(e), {kWeek, frame18 + 18.0}, 1);
  ASSERT_TRUE(decoder.klobuchar().valid);
  ASSERT_TRUE(decoder.utc().valid);
  EXPECT_TRUE(decoder.last_update().iono_utc);
  const KlobucharParameters k = brdc_2022_001_klobuchar();
  const int alpha_scale[4] = {-30, -27, -24, -24}, beta_scale[4] = {11, 14, 16, 16};  // 20.3.3.5.1.7
  for (int i = 0; i < 4; ++i) {
    expect_within_half_lsb(decoder.klobuchar().alpha[i], k.alpha[i], std::ldexp(1.0, alpha_scale[i]), "alpha", 1);
    expect_within_half_lsb(decoder.klobuchar().beta[i], k.beta[i], std::ldexp(1.0, beta_scale[i]), "beta", 1);
  }
  const UtcParameters u = brdc_2022_001_utc();
  expect_within_half_lsb(decoder.utc().a0_s, u.a0_s, std::ldexp(1.0, -30), "A0", 1);
  expect_within_half_lsb(decoder.utc().a1_sps, u.a1_sps, std::ldexp(1.0, -50), "A1", 1);
  EXPECT_EQ(decoder.utc().tot_s, u.tot_s);
  EXPECT_EQ(decoder.utc().wnt, u.wnt);
  EXPECT_EQ(decoder.utc().delta_t_ls_s, u.delta_t_ls_s);
  EXPECT_EQ(decoder.utc().wn_lsf, u.wn_lsf);
  EXPECT_EQ(decoder.utc().dn, u.dn);
  EXPECT_EQ(decoder.utc().delta_t_lsf_s, u.delta_t_lsf_s);
}

// Positions and scalings read with this test's own bit arithmetic from IS-GPS-200 Figure 20-1 /
// Tables 20-I, 20-III (subframe bit numbers counting parity), not with the decoder.
TEST(LnavTransmitter, FieldsSitAtIsGps200BitPositions) {
  const Ephemeris e = brdc_2022_001_ephemerides()[3];  // PRN 14: IODC 535, IODE 23
  const LnavTransmitter tx = make_transmitter(e);
  const SubframeBits sf1 = tx.subframe_starting_at({kWeek, kToe});
  const SubframeBits sf2 = tx.subframe_starting_at({kWeek, kToe + 6});
  const SubframeBits sf3 = tx.subframe_starting_at({kWeek, kToe + 12});
  for (const SubframeBits* sf : {&sf1, &sf2, &sf3}) EXPECT_EQ(raw_field(*sf, 1, 8), 0x8Bu);
  EXPECT_EQ(raw_field(sf1, 50, 3), 1u);
  EXPECT_EQ(raw_field(sf2, 50, 3), 2u);
  EXPECT_EQ(raw_field(sf3, 50, 3), 3u);
  EXPECT_EQ(raw_field(sf1, 31, 17), static_cast<std::uint32_t>((kToe + 6) / 6));
  EXPECT_EQ(raw_field(sf1, 61, 10), static_cast<std::uint32_t>(kWeek % 1024));
  EXPECT_EQ((raw_field(sf1, 83, 2) << 8) | raw_field(sf1, 211, 8), 535u);
  EXPECT_EQ(raw_field(sf1, 219, 16), static_cast<std::uint32_t>(e.toc_s / 16));
  EXPECT_EQ(signed_field(sf1, 197, 8), std::llround(e.tgd_s * std::ldexp(1.0, 31)));
  EXPECT_EQ(signed_field(sf1, 249, 16), std::llround(e.af1_sps * std::ldexp(1.0, 43)));
  EXPECT_EQ(signed_field(sf1, 271, 22), std::llround(e.af0_s * std::ldexp(1.0, 31)));
  EXPECT_EQ(raw_field(sf2, 61, 8), 23u);
  EXPECT_EQ(raw_field(sf3, 271, 8), 23u);
  EXPECT_EQ(signed_field(sf2, 69, 16), std::llround(e.crs_m * 32));
  const std::uint64_t sqrt_a = (std::uint64_t{raw_field(sf2, 227, 8)} << 24) | raw_field(sf2, 241, 24);
  EXPECT_EQ(sqrt_a, static_cast<std::uint64_t>(std::llround(e.sqrt_a_sqrtm * std::ldexp(1.0, 19))));
  const std::uint64_t ecc = (std::uint64_t{raw_field(sf2, 167, 8)} << 24) | raw_field(sf2, 181, 24);
  EXPECT_EQ(ecc, static_cast<std::uint64_t>(std::llround(e.e * std::ldexp(1.0, 33))));
  EXPECT_EQ(raw_field(sf2, 271, 16), static_cast<std::uint32_t>(e.toe_s / 16));
  const auto m0 = static_cast<std::int32_t>((raw_field(sf2, 107, 8) << 24) | raw_field(sf2, 121, 24));
  EXPECT_EQ(m0, std::llround(e.m0_rad / kPi * std::ldexp(1.0, 31)));
  const auto i0 = static_cast<std::int32_t>((raw_field(sf3, 137, 8) << 24) | raw_field(sf3, 151, 24));
  EXPECT_EQ(i0, std::llround(e.i0_rad / kPi * std::ldexp(1.0, 31)));
  EXPECT_EQ(signed_field(sf3, 241, 24), std::llround(e.omega_dot_radps / kPi * std::ldexp(1.0, 43)));
  EXPECT_EQ(signed_field(sf3, 279, 14), std::llround(e.idot_radps / kPi * std::ldexp(1.0, 43)));
  // Every word 2 and word 10 ends in D29 = D30 = 0 (parity-solving bits, IS-GPS-200 20.3.5.2).
  for (int k = 0; k < 5; ++k) {
    const SubframeBits sf = tx.subframe_starting_at({kWeek, kToe + 6.0 * k});
    EXPECT_EQ(sf[58] | sf[59], 0) << k;
    EXPECT_EQ(sf[298] | sf[299], 0) << k;
  }
}

TEST(LnavTransmitter, SubframeAndPageNumbering) {
  const LnavTransmitter tx = make_transmitter(brdc_2022_001_ephemerides()[0]);
  // Page SV IDs of subframe 4 (IS-GPS-200 Table 20-V) and subframe 5 (SV 1..24, page 25: 51).
  const int sf4_ids[25] = {57, 25, 26, 27, 28, 57, 29, 30, 31, 32, 57, 62, 52,
                           53, 54, 57, 55, 56, 58, 59, 57, 60, 61, 62, 63};
  const std::set<int> present = {1, 2, 4, 14, 18};
  for (int page = 1; page <= 25; ++page) {
    const double frame = 750.0 * 100 + 30.0 * (page - 1);  // (TOW / 30) mod 25 + 1 = page
    const SubframeBits sf4 = tx.subframe_starting_at({kWeek, frame + 18});
    const SubframeBits sf5 = tx.subframe_starting_at({kWeek, frame + 24});
    EXPECT_EQ(raw_field(sf4, 50, 3), 4u);
    EXPECT_EQ(raw_field(sf5, 50, 3), 5u);
    EXPECT_EQ(raw_field(sf4, 61, 2), 1u);  // data ID 01
    EXPECT_EQ(raw_field(sf5, 61, 2), 1u);
    const int id4 = sf4_ids[page - 1];
    const bool almanac4 = id4 >= 25 && id4 <= 32;
    EXPECT_EQ(static_cast<int>(raw_field(sf4, 63, 6)), almanac4 ? 0 : id4) << page;  // no SV 25-32: dummy
    const int id5 = page <= 24 ? (present.count(page) ? page : 0) : 51;
    EXPECT_EQ(static_cast<int>(raw_field(sf5, 63, 6)), id5) << page;
    if (page <= 24 && present.count(page)) {  // almanac of a present SV: e (2^-21), sqrt A (2^-11)
      std::optional<Ephemeris> e;
      for (const auto& x : brdc_2022_001_ephemerides())
        if (x.prn == page) e = x;
      ASSERT_TRUE(e.has_value());
      EXPECT_NEAR(raw_field(sf5, 69, 16) * std::ldexp(1.0, -21), e->e, std::ldexp(0.5, -21));
      EXPECT_NEAR(raw_field(sf5, 151, 24) * std::ldexp(1.0, -11), e->sqrt_a_sqrtm, std::ldexp(0.5, -11));
      EXPECT_EQ(raw_field(sf5, 137, 8), 0u);  // healthy
    } else if (page <= 24) {                  // dummy SV: alternating 1010 fill from bit 9 of word 3
      EXPECT_EQ(raw_field(sf5, 69, 16), 0xAAAAu);
      EXPECT_EQ(raw_field(sf5, 91, 24), 0xAAAAAAu);
    }
  }
  // Subframe 5 page 25: toa = 518400 - 518400 mod 4096, WNa = 2190 mod 256, SV 2 healthy, SV 3 absent.
  const SubframeBits p25 = tx.subframe_starting_at({kWeek, 750.0 * 100 + 30.0 * 24 + 24});
  EXPECT_EQ(raw_field(p25, 69, 8), static_cast<std::uint32_t>(std::floor(kToe / 4096)));
  EXPECT_EQ(raw_field(p25, 77, 8), static_cast<std::uint32_t>(kWeek % 256));
  EXPECT_EQ(raw_field(p25, 97, 6), 0u);      // SV 2
  EXPECT_EQ(raw_field(p25, 103, 6), 0x3Fu);  // SV 3
}

TEST(LnavDecoder, DetectsEverySingleBitErrorOfEverySubframe) {
  const LnavTransmitter tx = make_transmitter(brdc_2022_001_ephemerides()[1]);
  for (int k = 0; k < 5; ++k) {
    const SubframeBits good = tx.subframe_starting_at({kWeek, kToe + 6.0 * k});
    ASSERT_EQ(decode_lnav_subframe(good).status, LnavStatus::kOk);
    for (int b = 0; b < 300; ++b) {
      SubframeBits bad = good;
      bad[static_cast<std::size_t>(b)] ^= 1;
      const LnavSubframeResult r = decode_lnav_subframe(bad);
      if (b < 8) {
        EXPECT_EQ(r.status, LnavStatus::kNoPreamble) << "subframe " << k + 1 << " bit " << b + 1;
      } else {
        EXPECT_EQ(r.status, LnavStatus::kParityError) << "subframe " << k + 1 << " bit " << b + 1;
        EXPECT_EQ(r.failed_word, b / 30 + 1) << "subframe " << k + 1 << " bit " << b + 1;
      }
    }
  }
}

TEST(LnavDecoder, ParityFailureIsCountedAndSubframeDropped) {
  const Ephemeris e = brdc_2022_001_ephemerides()[0];
  const LnavTransmitter tx = make_transmitter(e);
  LnavDecoder decoder(e.prn, kWeek);
  std::array<std::uint8_t, 2> prev{0, 0};
  for (int k = 0; k < 3; ++k) {
    SubframeBits bits = tx.subframe_starting_at({kWeek, kToe + 6.0 * k});
    if (k == 1) bits[150] ^= 1;  // one error in subframe 2
    EXPECT_EQ(decoder.add_bits(bits, prev), k == 1 ? LnavStatus::kParityError : LnavStatus::kOk);
    prev = {bits[298], bits[299]};
  }
  EXPECT_EQ(decoder.counters().parity_errors, 1);
  EXPECT_EQ(decoder.counters().accepted, 2);
  EXPECT_FALSE(decoder.ephemeris().has_value());
  // The next frame's clean subframe 2 completes the set.
  feed(decoder, tx, {kWeek, kToe + 36.0}, 1);
  EXPECT_TRUE(decoder.ephemeris().has_value());
  EXPECT_TRUE(decoder.last_update().ephemeris);
}

TEST(LnavDecoder, InvertedSubframeDecodesIdentically) {
  const LnavTransmitter tx = make_transmitter(brdc_2022_001_ephemerides()[2]);
  std::array<std::uint8_t, 2> prev{0, 0};
  for (int k = 0; k < 10; ++k) {
    const SubframeBits bits = tx.subframe_starting_at({kWeek, kToe + 6.0 * k});
    SubframeBits inv = bits;
    for (auto& b : inv) b ^= 1;
    const std::array<std::uint8_t, 2> inv_prev{static_cast<std::uint8_t>(prev[0] ^ 1),
                                               static_cast<std::uint8_t>(prev[1] ^ 1)};
    const LnavSubframeResult upright = decode_lnav_subframe(bits, prev);
    for (const LnavSubframeResult& r : {decode_lnav_subframe(inv, inv_prev), decode_lnav_subframe(inv)}) {
      ASSERT_EQ(upright.status, LnavStatus::kOk);
      ASSERT_EQ(r.status, LnavStatus::kOk);
      EXPECT_FALSE(upright.subframe.inverted);
      EXPECT_TRUE(r.subframe.inverted);
      EXPECT_EQ(r.subframe.words, upright.subframe.words);
      EXPECT_EQ(r.subframe.tow_count, upright.subframe.tow_count);
      EXPECT_EQ(r.subframe.subframe_id, upright.subframe.subframe_id);
    }
    prev = {bits[298], bits[299]};
  }
  // An inverted stream yields the same ephemeris.
  LnavDecoder decoder(4, kWeek);
  for (int k = 0; k < 3; ++k) {
    SubframeBits inv = tx.subframe_starting_at({kWeek, kToe + 6.0 * k});
    for (auto& b : inv) b ^= 1;
    ASSERT_EQ(decoder.add_bits(inv, std::array<std::uint8_t, 2>{1, 1}), LnavStatus::kOk);
  }
  ASSERT_TRUE(decoder.ephemeris().has_value());
  EXPECT_EQ(decoder.ephemeris()->iodc, 990);
}

TEST(LnavDecoder, HowTowCountIsNextSubframeStart) {
  const LnavTransmitter tx = make_transmitter(brdc_2022_001_ephemerides()[0]);
  LnavDecoder decoder(1, kWeek);
  // 20 subframes running over the end of week 2190.
  const GpsTime first{kWeek, kSecondsPerWeek - 60.0};
  for (int k = 0; k < 20; ++k) {
    const GpsTime start = add_seconds(first, 6.0 * k);
    const GpsTime next = add_seconds(start, 6.0);
    const LnavSubframeResult r = decode_lnav_subframe(tx.subframe_starting_at(start));
    ASSERT_EQ(r.status, LnavStatus::kOk);
    EXPECT_EQ(r.subframe.tow_count * 6.0, next.tow_s) << k;
    EXPECT_EQ(r.subframe.subframe_id, static_cast<int>(start.tow_s / 6) % 5 + 1) << k;
    decoder.add(r.subframe);
    ASSERT_TRUE(decoder.last_subframe_start().has_value());
    EXPECT_EQ(decoder.last_subframe_start()->week, start.week) << k;
    EXPECT_EQ(decoder.last_subframe_start()->tow_s, start.tow_s) << k;
  }
}

TEST(LnavDecoder, FrameStartingAtSubframe4YieldsEphemerisAfterSubframe3) {
  const Ephemeris e = brdc_2022_001_ephemerides()[4];  // PRN 18: IODC 868, IODE 100
  const LnavTransmitter tx = make_transmitter(e);
  LnavDecoder decoder(e.prn, kWeek);
  std::array<std::uint8_t, 2> prev{0, 0};
  for (int k = 0; k < 5; ++k) {  // subframes 4, 5, 1, 2, 3
    const SubframeBits bits = tx.subframe_starting_at({kWeek, kToe + 18.0 + 6.0 * k});
    ASSERT_EQ(decoder.add_bits(bits, prev), LnavStatus::kOk);
    prev = {bits[298], bits[299]};
    EXPECT_EQ(decoder.ephemeris().has_value(), k == 4) << k;
    EXPECT_EQ(decoder.last_update().ephemeris, k == 4) << k;
  }
  EXPECT_EQ(decoder.ephemeris()->iodc, 868);
  EXPECT_EQ(decoder.ephemeris()->iode, 100);
  // The same data again next frame is no news.
  feed(decoder, tx, {kWeek, kToe + 30.0}, 3);
  EXPECT_FALSE(decoder.last_update().ephemeris);
}

TEST(LnavDecoder, InconsistentIssueOfDataIsNotCombined) {
  Ephemeris old_e = brdc_2022_001_ephemerides()[0];  // IODE 39
  Ephemeris new_e = old_e;
  new_e.iode = 40, new_e.iodc = 40, new_e.toe_s = kToe + 7200, new_e.toc_s = new_e.toe_s;
  const LnavTransmitter tx_old = make_transmitter(old_e), tx_new = make_transmitter(new_e);
  LnavDecoder decoder(1, kWeek);
  feed(decoder, tx_new, {kWeek, kToe}, 1);        // subframe 1 of the new upload
  feed(decoder, tx_old, {kWeek, kToe + 6.0}, 2);  // subframes 2, 3 of the old one
  EXPECT_FALSE(decoder.ephemeris().has_value());
  EXPECT_GE(decoder.counters().inconsistent, 1);
  feed(decoder, tx_new, {kWeek, kToe + 36.0}, 2);  // new subframes 2, 3
  ASSERT_TRUE(decoder.ephemeris().has_value());
  EXPECT_EQ(decoder.ephemeris()->iode, 40);
  EXPECT_EQ(decoder.ephemeris()->toe_s, kToe + 7200);
}

TEST(LnavDecoder, WeekResolvedAgainstReferenceAndToeInNextWeek) {
  Ephemeris e = brdc_2022_001_ephemerides()[0];
  for (int reference : {kWeek - 511, kWeek, kWeek + 511}) {
    LnavDecoder decoder(1, reference);
    feed(decoder, make_transmitter(e), {kWeek, kToe}, 3);
    ASSERT_TRUE(decoder.ephemeris().has_value());
    EXPECT_EQ(decoder.ephemeris()->week, kWeek) << reference;
  }
  // An ephemeris with toe at the start of week 2191 sent during the last frame of week 2190.
  e.week = kWeek + 1, e.toe_s = 0.0, e.toc_s = 0.0;
  LnavDecoder decoder(1, kWeek);
  feed(decoder, make_transmitter(e), {kWeek, kSecondsPerWeek - 30.0}, 3);
  ASSERT_TRUE(decoder.ephemeris().has_value());
  EXPECT_EQ(decoder.ephemeris()->week, kWeek + 1);
  EXPECT_EQ(decoder.ephemeris()->toe_s, 0.0);
}

TEST(LnavTransmitter, DataSymbolsAcrossSubframeAndWeekBoundary) {
  LnavTransmitter tx = make_transmitter(brdc_2022_001_ephemerides()[0]);
  // Symbols in the middle of each 20 ms bit from 12 s before to 12 s after the week boundary: four
  // subframes whose bits must decode with parity chained across the subframe edges.
  const GpsTime first{kWeek, kSecondsPerWeek - 12.0};
  std::vector<std::uint8_t> stream;
  for (int i = 0; i < 4 * 300; ++i) {
    const int s = tx.data_symbol_at(add_seconds(first, 0.02 * i + 0.01));
    ASSERT_TRUE(s == 1 || s == -1);
    stream.push_back(s < 0 ? 1 : 0);
  }
  std::array<std::uint8_t, 2> prev{0, 0};
  const int expected_id[4] = {4, 5, 1, 2};
  const int expected_count[4] = {100799, 0, 1, 2};
  for (int k = 0; k < 4; ++k) {
    std::span<const std::uint8_t, 300> bits(stream.data() + 300 * k, 300);
    const LnavSubframeResult r = decode_lnav_subframe(bits, prev);
    ASSERT_EQ(r.status, LnavStatus::kOk) << k;
    EXPECT_EQ(r.subframe.subframe_id, expected_id[k]);
    EXPECT_EQ(r.subframe.tow_count, expected_count[k]);
    prev = {bits[298], bits[299]};
  }
  // At bit edges (start + 20 ms k) the new bit is on the air; the symbol equals the subframe's bit.
  const GpsTime start{kWeek + 1, 6.0};
  const SubframeBits bits = tx.subframe_starting_at(start);
  for (int k = 0; k < 300; ++k) {
    EXPECT_EQ(tx.data_symbol_at(add_seconds(start, 0.02 * k)), bits[static_cast<std::size_t>(k)] ? -1 : 1) << k;
  }
}

// The almanac of PRN 1 (subframe 5 page 1) against the ephemeris moved to toa = 516096 s (518400 s
// taken down to a multiple of 2^12 s): positions and scale factors of IS-GPS-200 Table 20-VI.
TEST(LnavTransmitter, AlmanacPageHoldsEphemerisAtToa) {
  const Ephemeris e = brdc_2022_001_ephemerides()[0];
  const LnavTransmitter tx = make_transmitter(e);
  EXPECT_EQ(tx.almanac_reference().tow_s, 516096.0);
  const SubframeBits p1 = tx.subframe_starting_at({kWeek, 750.0 * 100 + 24});  // page 1 of subframe 5
  ASSERT_EQ(raw_field(p1, 63, 6), 1u);
  const double dt = 516096.0 - kToe;
  EXPECT_EQ(raw_field(p1, 91, 8) * 4096.0, 516096.0);
  // delta i is relative to 0.30 semicircles, 2^-19 semicircles.
  EXPECT_NEAR((signed_field(p1, 99, 16) * std::ldexp(1.0, -19) + 0.30) * kPi, e.i0_rad + e.idot_radps * dt,
              std::ldexp(0.5, -19) * kPi + 1e-15);
  EXPECT_NEAR(signed_field(p1, 121, 16) * std::ldexp(1.0, -38) * kPi, e.omega_dot_radps, std::ldexp(0.5, -38) * kPi);
  EXPECT_NEAR(signed_field(p1, 211, 24) * std::ldexp(1.0, -23) * kPi, e.omega_rad, std::ldexp(0.5, -23) * kPi);
  // M0 moved by the mean motion over dt (n = sqrt(mu / A^3) + delta n), wrapped to [-pi, pi).
  const double a = e.sqrt_a_sqrtm * e.sqrt_a_sqrtm;
  const double n = std::sqrt(3.986005e14 / (a * a * a)) + e.delta_n_radps;
  const double m_toa = std::remainder(e.m0_rad + n * dt, 2.0 * kPi);
  EXPECT_NEAR(signed_field(p1, 241, 24) * std::ldexp(1.0, -23) * kPi, m_toa, std::ldexp(0.5, -23) * kPi + 1e-12);
  // af0: 8 MSBs at bits 271-278, 3 LSBs at 290-292, 2^-20 s; af1: bits 279-289, 2^-38 s/s.
  std::int64_t af0 = (std::int64_t{raw_field(p1, 271, 8)} << 3) | raw_field(p1, 290, 3);
  if (af0 >= 1024) af0 -= 2048;
  EXPECT_NEAR(af0 * std::ldexp(1.0, -20), e.af0_s + e.af1_sps * dt, std::ldexp(0.5, -20));
  EXPECT_NEAR(signed_field(p1, 279, 11) * std::ldexp(1.0, -38), e.af1_sps, std::ldexp(0.5, -38));
}

TEST(LnavTransmitter, RejectsValuesThatCannotBeBroadcast) {
  Ephemeris e = brdc_2022_001_ephemerides()[0];
  e.af0_s = 1.0e-3;  // beyond the 22-bit 2^-31 s range of +-0.977 ms
  EXPECT_THROW(make_transmitter(e), InputError);
  e = brdc_2022_001_ephemerides()[0];
  e.iodc = 1024;
  EXPECT_THROW(make_transmitter(e), InputError);
  e = brdc_2022_001_ephemerides()[0];
  e.e = 1.0;  // 32 bits of 2^-33: e < 0.5
  EXPECT_THROW(make_transmitter(e), InputError);
}

// A whole 25-page master frame (125 subframes) through the decoder: every almanac the transmitter made from
// the 2022-01-01 broadcast ephemerides comes back within half an LSB of the ephemeris moved to toa
// (Table 20-VI scales), and the almanac orbit places each satellite within 5 km of its ephemeris orbit for
// +-2 h around toa (the almanac drops the harmonic terms, ~0.1-1 km, and delta n, < 1 km over 2 h).
TEST(LnavDecoder, AlmanacRoundTripOfAWholeMasterFrame) {
  const std::vector<Ephemeris> all = brdc_2022_001_ephemerides();
  const LnavTransmitter tx = make_transmitter(all[0]);
  LnavDecoder decoder(all[0].prn, kWeek);
  feed(decoder, tx, {kWeek, kToe}, 125);
  const GpsTime toa = tx.almanac_reference();
  int checked = 0;
  for (const Ephemeris& e : all) {
    const auto& a = decoder.almanacs()[static_cast<std::size_t>(e.prn)];
    ASSERT_TRUE(a.has_value()) << "PRN " << e.prn;
    ++checked;
    EXPECT_EQ(a->week, toa.week);
    EXPECT_EQ(a->toa_s, toa.tow_s);
    const double dt = seconds_between(toa, e.toe());
    const double sqrt_a = e.sqrt_a_sqrtm;
    const double n = std::sqrt(3.986005e14 / (sqrt_a * sqrt_a * sqrt_a * sqrt_a * sqrt_a * sqrt_a)) + e.delta_n_radps;
    expect_within_half_lsb(a->e, e.e, std::ldexp(1.0, -21), "e", e.prn);
    expect_within_half_lsb(a->i_rad, e.i0_rad + e.idot_radps * dt, std::ldexp(1.0, -19) * kPi, "i", e.prn);
    expect_within_half_lsb(a->omega_dot_radps, e.omega_dot_radps, std::ldexp(1.0, -38) * kPi, "Omega dot", e.prn);
    expect_within_half_lsb(a->sqrt_a_sqrtm, sqrt_a, std::ldexp(1.0, -11), "sqrt A", e.prn);
    const double lsb_angle = std::ldexp(1.0, -23) * kPi;
    EXPECT_LE(std::abs(std::remainder(a->omega0_rad - (e.omega0_rad + e.omega_dot_radps * dt), 2 * kPi)),
              0.5 * lsb_angle + 1e-12)
        << e.prn;
    EXPECT_LE(std::abs(std::remainder(a->omega_rad - e.omega_rad, 2 * kPi)), 0.5 * lsb_angle + 1e-12) << e.prn;
    EXPECT_LE(std::abs(std::remainder(a->m0_rad - (e.m0_rad + n * dt), 2 * kPi)), 0.5 * lsb_angle + 1e-12) << e.prn;
    expect_within_half_lsb(a->af0_s, e.af0_s + e.af1_sps * seconds_between(toa, e.toc()), std::ldexp(1.0, -20), "af0",
                           e.prn);
    expect_within_half_lsb(a->af1_sps, e.af1_sps, std::ldexp(1.0, -38), "af1", e.prn);
    // Health: the 3-bit NAV summary (all bad when the 6-bit summary bit is set) and the 5-bit signal code.
    EXPECT_EQ(a->health & 0x1F, e.health & 0x1F);
    EXPECT_EQ((a->health >> 5) != 0, (e.health & 0x20) != 0);
    const Ephemeris orbit = almanac_orbit(*a);
    for (double t : {-7200.0, 0.0, 3600.0, 7200.0}) {
      const GpsTime when = add_seconds(toa, t);
      const double d = (satellite_state(orbit, when).r_e_m - satellite_state(e, when).r_e_m).norm();
      EXPECT_LT(d, 5e3) << "PRN " << e.prn << " at toa " << t << " s";
    }
  }
  EXPECT_EQ(checked, static_cast<int>(all.size()));
  // PRNs without an almanac in the source are dummy pages: nothing decoded for them.
  for (int prn = 1; prn <= 32; ++prn) {
    const bool present = std::any_of(all.begin(), all.end(), [prn](const auto& e) { return e.prn == prn; });
    EXPECT_EQ(decoder.almanacs()[static_cast<std::size_t>(prn)].has_value(), present) << prn;
  }
}

// Another generator's quantisation: fields rounded toward zero decode within one LSB of the broadcast value,
// never farther from zero than it (|decoded| <= |value|), and differ from our round-to-nearest encoding in
// about half of the fields (the half whose remainder is >= LSB/2).
TEST(LnavTransmitter, TowardZeroRoundingDecodesWithinOneLsbTowardZero) {
  LnavConventions truncating;
  truncating.field_rounding = FieldRounding::kTowardZero;
  int differing_words = 0, words = 0;
  for (const Ephemeris& e : brdc_2022_001_ephemerides()) {
    const LnavTransmitter nearest = make_transmitter(e);
    const LnavTransmitter toward_zero(e, brdc_2022_001_klobuchar(), brdc_2022_001_utc(), brdc_2022_001_ephemerides(),
                                      truncating);
    LnavDecoder decoder(e.prn, kWeek);
    feed(decoder, toward_zero, {kWeek, kToe}, 3);
    ASSERT_TRUE(decoder.ephemeris().has_value()) << e.prn;
    const Ephemeris& d = *decoder.ephemeris();
    const auto check = [&](double decoded, double value, double lsb, const char* what) {
      const double ulps = 4.0 * std::numeric_limits<double>::epsilon() * std::abs(value);
      EXPECT_LE(std::abs(decoded - value), lsb + ulps) << what << " PRN " << e.prn;
      EXPECT_LE(std::abs(decoded), std::abs(value) + ulps) << what << " PRN " << e.prn;
    };
    check(d.af0_s, e.af0_s, std::ldexp(1.0, -31), "af0");
    check(d.af1_sps, e.af1_sps, std::ldexp(1.0, -43), "af1");
    check(d.crs_m, e.crs_m, std::ldexp(1.0, -5), "Crs");
    check(d.e, e.e, std::ldexp(1.0, -33), "e");
    check(d.sqrt_a_sqrtm, e.sqrt_a_sqrtm, std::ldexp(1.0, -19), "sqrt A");
    check(d.m0_rad, e.m0_rad, std::ldexp(kPi, -31), "M0");
    check(d.i0_rad, e.i0_rad, std::ldexp(kPi, -31), "i0");
    check(d.idot_radps, e.idot_radps, std::ldexp(kPi, -43), "IDOT");
    for (int k = 0; k < 3; ++k) {
      const GpsTime start = add_seconds({kWeek, kToe}, 6.0 * k);
      const LnavDataWords a = nearest.subframe_data(start), b = toward_zero.subframe_data(start);
      for (int w = 2; w < 10; ++w) {
        ++words;
        differing_words += a[static_cast<std::size_t>(w)] != b[static_cast<std::size_t>(w)];
      }
    }
  }
  // Words 3-10 of subframes 1-3 hold 1-3 rounded fields each: with a remainder uniform in [0, 1) LSB, a word
  // keeps its bits only when each of its fields' remainders is below LSB/2, so ~25-50 % of words stay.
  std::printf("toward-zero rounding changes %d of %d words 3-10 of subframes 1-3\n", differing_words, words);
  EXPECT_GT(differing_words, words / 3) << differing_words << " of " << words;
  EXPECT_LT(differing_words, words) << differing_words << " of " << words;
}

// Random subframe 4/5 pages: valid parity, dummy-SV pages (nothing decoded from them), page 18 intact, the bits
// fixed by the seed and changed by another seed; subframes 1-3 unchanged.
TEST(LnavTransmitter, RandomPagesKeepParityAndPage18AndDependOnTheSeed) {
  const Ephemeris e = brdc_2022_001_ephemerides()[3];
  LnavConventions random_pages;
  random_pages.random_pages = true;
  random_pages.page_seed = 11;
  LnavConventions other_seed = random_pages;
  other_seed.page_seed = 12;
  const LnavTransmitter ours = make_transmitter(e);
  const auto tx = [&](const LnavConventions& c) {
    return LnavTransmitter(e, brdc_2022_001_klobuchar(), brdc_2022_001_utc(), brdc_2022_001_ephemerides(), c);
  };
  const LnavTransmitter random = tx(random_pages), random_again = tx(random_pages), other = tx(other_seed);
  LnavDecoder decoder(e.prn, kWeek);
  feed(decoder, random, {kWeek, kToe}, 5 * 25);  // a whole master frame: every page once, parity checked in feed
  EXPECT_EQ(decoder.counters().parity_errors, 0);
  EXPECT_TRUE(decoder.klobuchar().valid);  // page 18 decoded
  for (int prn = 1; prn <= 32; ++prn) EXPECT_FALSE(decoder.almanacs()[static_cast<std::size_t>(prn)].has_value());
  int differing = 0;
  for (int k = 0; k < 5 * 25; ++k) {
    const GpsTime start = add_seconds({kWeek, kToe}, 6.0 * k);
    const int id = lnav_subframe_id_at(start.tow_s);
    const LnavDataWords a = ours.subframe_data(start), b = random.subframe_data(start);
    EXPECT_EQ(b, random_again.subframe_data(start));
    const bool page18 = id == 4 && lnav_page_at(start.tow_s) == 18;
    if (id <= 3 || page18) {
      EXPECT_EQ(a, b) << "subframe " << id;
      continue;
    }
    EXPECT_NE(b, other.subframe_data(start));
    differing += a != b;
  }
  EXPECT_EQ(differing, 2 * 25 - 1);
}

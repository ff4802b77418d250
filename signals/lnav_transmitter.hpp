// SPDX-License-Identifier: GPL-3.0-or-later
// What a GPS satellite broadcasts on LNAV: the 50 bit/s data stream of 5-subframe frames built from one
// satellite's ephemeris and clock, the ionosphere/UTC parameters and (optionally) an almanac made from a
// set of ephemerides, with TLM, HOW (TOW count of the next subframe) and IS-GPS-200 20.3.5 parity.
// Used by the IF synthesiser; the receiver's decoder (lnav_decoder.hpp) reads the same bits back.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "signals/ephemeris.hpp"
#include "signals/gps_time.hpp"
#include "signals/lnav_fields.hpp"

namespace ultratrack::signals {

// The 300 transmitted bits of one subframe (0/1, first transmitted bit first), parity applied and
// data bits already complemented where the previous word's D30* demands it.
using SubframeBits = std::array<std::uint8_t, 300>;

// Applies parity to ten 24-bit data words (words 2 and 10: their bits 23-24 are solved so that D29 = D30
// = 0) and returns the transmitted bits. The chain starts from D29* = D30* = 0, which every LNAV subframe
// can assume because the previous subframe's word 10 ends in 00.
SubframeBits encode_lnav_subframe(const LnavDataWords& data);

// Subframe ID (1..5) and subframe 4/5 page number (1..25) of the subframe starting at tow_s (IS-GPS-200
// 20.3.4.1: subframe 1 starts at multiples of 30 s; here the 25-page cycle restarts at every week start).
int lnav_subframe_id_at(double tow_s);
int lnav_page_at(double tow_s);

// Choices another generator may make differently from ours (a receiver must not depend on ours):
// - field_rounding: ephemeris and clock fields of subframes 1-3 rounded to nearest (ours) or toward zero;
// - random_pages: subframe 4/5 words 3-10 carry seeded random bits instead of almanac and health pages (what a
//   receiver cannot predict from any nav file), marked as dummy-SV pages (SV ID 0) so that no decoder takes
//   them for almanacs or health; page 18 (ionosphere and UTC, SV ID 56) keeps its content.
struct LnavConventions {
  FieldRounding field_rounding = FieldRounding::kNearest;
  bool random_pages = false;
  std::uint64_t page_seed = 0;  // random_pages: with the PRN and the subframe's time, fixes the bits
};

class LnavTransmitter {
 public:
  // almanac_source: ephemerides of the whole constellation for subframe 4/5 almanac pages (may be empty:
  // the pages then carry dummy-satellite almanacs as IS-GPS-200 allows).
  LnavTransmitter(Ephemeris ephemeris, KlobucharParameters iono, UtcParameters utc,
                  std::vector<Ephemeris> almanac_source = {}, LnavConventions conventions = {});

  // The subframe whose first bit starts at GPS time (week, tow) where tow is a multiple of 6 s (any other
  // start is taken back to the multiple of 6 s at or before it). WN is transmitted as start.week mod 1024,
  // the HOW carries the TOW count of start + 6 s. Throws InputError when a field does not fit its bits.
  SubframeBits subframe_starting_at(const GpsTime& start) const;
  // The same before parity: the ten 24-bit data words (HOW and word 10 parity bits left 0).
  LnavDataWords subframe_data(const GpsTime& start) const;

  // The data symbol (+1 for bit 0, -1 for bit 1) on the air at GPS transmit time t.
  // Cheap when called with increasing t (caches the current subframe).
  int data_symbol_at(const GpsTime& t);

  // Almanac reference time of subframe 5 page 25: the transmitted ephemeris's toe taken down to a
  // multiple of 4096 s, in the ephemeris week.
  GpsTime almanac_reference() const;

 private:
  LnavDataWords subframe1(int transmit_week) const;
  LnavDataWords subframe2() const;
  LnavDataWords subframe3() const;
  LnavDataWords subframe4(int page) const;
  LnavDataWords subframe5(int page) const;
  void almanac_page(LnavDataWords& w, int prn) const;
  const Ephemeris* almanac_of(int prn) const;
  void randomise_page(LnavDataWords& w, const GpsTime& start) const;

  Ephemeris ephemeris_;
  KlobucharParameters iono_;
  UtcParameters utc_;
  std::vector<Ephemeris> almanac_source_;
  LnavConventions conventions_;
  GpsTime cached_start_{-1, 0.0};
  SubframeBits cached_bits_{};
};

}  // namespace ultratrack::signals

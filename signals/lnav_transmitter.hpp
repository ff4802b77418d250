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

namespace ultratrack::signals {

// The 300 transmitted bits of one subframe (0/1, first transmitted bit first), parity applied and
// data bits already complemented where the previous word's D30* demands it.
using SubframeBits = std::array<std::uint8_t, 300>;

class LnavTransmitter {
 public:
  // almanac_source: ephemerides of the whole constellation for subframe 4/5 almanac pages (may be empty:
  // the pages then carry dummy-satellite almanacs as IS-GPS-200 allows).
  LnavTransmitter(Ephemeris ephemeris, KlobucharParameters iono, UtcParameters utc,
                  std::vector<Ephemeris> almanac_source = {});

  // The subframe whose first bit starts at GPS time (week, tow) where tow is a multiple of 6 s.
  SubframeBits subframe_starting_at(const GpsTime& start) const;

  // The data symbol (+1 for bit 0, -1 for bit 1) on the air at GPS transmit time t.
  // Cheap when called with increasing t (caches the current subframe).
  int data_symbol_at(const GpsTime& t);

 private:
  Ephemeris ephemeris_;
  KlobucharParameters iono_;
  UtcParameters utc_;
  std::vector<Ephemeris> almanac_source_;
  GpsTime cached_start_{-1, 0.0};
  SubframeBits cached_bits_{};
};

}  // namespace ultratrack::signals

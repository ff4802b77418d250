// Navigation bit prediction for data wipe-off: the LNAV bit (0/1) a satellite transmits at a GPS transmit time,
// where it can be known. Two sources: (a) the channel's own decoded subframes: subframes 1-3 repeat every 30 s
// while IODE/IODC stay the same, so the next frame's subframes 1-3 are re-encoded from their data words with the
// TLM, the HOW of that subframe (TOW count, subframe ID) and the IS-GPS-200 parity (signals' encoder); the TLM
// and HOW words of subframes 4 and 5 are known as well, their pages are not. (b) a supplied source: broadcast
// ephemerides (a nav file), re-encoded by signals' LnavTransmitter exactly as `ultratrack simulate` does
// (ephemeris per PRN selected at the given time; the selected set for the almanac pages), which knows every bit
// of a simulated file. Real recordings only have (a): their subframe 4/5 pages stay unknown.
#pragma once

#include <array>
#include <bitset>
#include <cstdint>
#include <optional>
#include <vector>

#include "signals/ephemeris.hpp"
#include "signals/gps_time.hpp"
#include "signals/lnav_fields.hpp"
#include "signals/lnav_subframe.hpp"
#include "signals/lnav_transmitter.hpp"

namespace ultratrack::receiver {

class NavBitPredictor {
 public:
  // (b): the transmitter of `prn` built from the broadcast sets as the simulator builds it, selecting at time
  // `at` (ephemeris of each PRN: signals::select_ephemeris). False (and nothing changes) when no set qualifies.
  bool supply_navigation(int prn, const std::vector<signals::Ephemeris>& sets, const signals::KlobucharParameters& iono,
                         const signals::UtcParameters& utc, const signals::GpsTime& at, bool include_unhealthy = false);
  bool supplied() const { return transmitter_.has_value(); }
  // (a): a parity-checked subframe that began at GPS transmit time `start`. Subframes 1-3 replace the stored
  // ones (a new IODE then predicts the new data from its next repetition on); every subframe gives the TLM and
  // the HOW's alert and anti-spoof flags.
  void add_subframe(const signals::LnavSubframe& subframe, const signals::GpsTime& start);

  // The data bit (0/1) of the bit on the air during [t, t + 20 ms) (t on a bit edge; t may be a few ns off it),
  // or nothing when unknown. Cheap for increasing t within a subframe (one subframe is cached).
  std::optional<int> bit_at(const signals::GpsTime& t);

 private:
  void build(const signals::GpsTime& subframe_start);

  std::optional<signals::LnavTransmitter> transmitter_;
  std::optional<std::uint32_t> tlm_;  // word 1 data bits (preamble, TLM message, integrity, reserved)
  std::uint32_t alert_ = 0, anti_spoof_ = 0;  // HOW flags
  struct Stored {
    signals::LnavDataWords words{};
    int week = 0;
  };
  std::array<std::optional<Stored>, 3> subframes_{};  // latest subframes 1, 2, 3
  signals::GpsTime cached_start_{-1, 0.0};
  int cached_version_ = -1;
  int version_ = 0;  // bumped by every change of the stored data
  signals::SubframeBits bits_{};
  std::bitset<300> known_;
};

}  // namespace ultratrack::receiver

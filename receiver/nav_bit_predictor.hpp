// SPDX-License-Identifier: GPL-3.0-or-later
// Navigation bit prediction for data wipe-off: the LNAV bit (0/1) a satellite transmits at a GPS transmit time,
// where it can be known. The source (receiver/nav_bit_source.hpp):
// kDecoded (default): the channel's own decoded subframes. Subframes 1-3 repeat every 30 s while IODE/IODC stay
// the same, so the next frame's subframes 1-3 are re-encoded from their data words with the TLM, the HOW of that
// subframe (TOW count, subframe ID) and the IS-GPS-200 parity (signals' encoder); the TLM and HOW words of
// subframes 4 and 5 are known as well, their pages are not. A supplied nav file's subframe 1-3 words (3-10) are
// verified word by word against words the channel read from the signal (add_word: a word whose own parity holds,
// also inside a subframe that failed; every word of a decoded subframe): a word is trusted when its data equal the
// nav file's (word 10 without its two parity-solving bits) and the two bits before it (D29*, D30*, which set its
// polarity on the air) equal the nav file's encoding, and only while the word holding that subframe's issue of data
// (IODC: words 3 and 8 of subframe 1; IODE: word 3 of subframe 2, word 10 of subframe 3) is trusted too. A word that
// disagrees is never used (and an issue-of-data word that disagrees withdraws its subframe). A subframe decoded
// whole is predicted from its own data; otherwise its trusted nav-file words (and TLM/HOW) are known, the rest not:
// the nav file never adds a bit the signal has not shown. stop() (the contradiction check tripped) leaves every bit
// unknown until a decoded subframe 1-3 brings data that differ from the stored ones.
// kOracle: a supplied nav file re-encoded by signals' LnavTransmitter exactly as `ultratrack simulate` does
// (ephemeris per PRN selected at the given time; the selected set for the almanac pages), which knows every bit
// of a simulated file and guesses on any other; without a nav file, as kDecoded. For simulation studies only.
#pragma once

#include <array>
#include <bitset>
#include <cstdint>
#include <optional>
#include <vector>

#include "receiver/nav_bit_source.hpp"
#include "signals/ephemeris.hpp"
#include "signals/gps_time.hpp"
#include "signals/lnav_fields.hpp"
#include "signals/lnav_subframe.hpp"
#include "signals/lnav_transmitter.hpp"

namespace ultratrack::receiver {

class NavBitPredictor {
 public:
  explicit NavBitPredictor(NavBitSource source = NavBitSource::kDecoded) : source_(source) {}
  NavBitSource source() const { return source_; }
  void set_source(NavBitSource source) {
    source_ = source;
    ++version_;
  }

  // The transmitter of `prn` built from the broadcast sets as the simulator builds it, selecting at time `at`
  // (ephemeris of each PRN: signals::select_ephemeris). False (and nothing changes) when no set qualifies.
  // kOracle: every bit from it; kDecoded: decoded subframes 1-3 are checked against it (nav_words_*).
  bool supply_navigation(int prn, const std::vector<signals::Ephemeris>& sets, const signals::KlobucharParameters& iono,
                         const signals::UtcParameters& utc, const signals::GpsTime& at, bool include_unhealthy = false);
  bool supplied() const { return transmitter_.has_value(); }
  // A parity-checked subframe that began at GPS transmit time `start`. Subframes 1-3 replace the stored ones (a
  // new IODE then predicts the new data from its next repetition on); every subframe gives the TLM and the HOW's
  // alert and anti-spoof flags.
  void add_subframe(const signals::LnavSubframe& subframe, const signals::GpsTime& start);
  // A word read on its own: index 0..9 in the subframe that began at GPS transmit time `start`, data24 = d1..d24
  // (polarity restored), its parity checked with the received bits before it (prev_d29, prev_d30: 0/1).
  void add_word(const signals::GpsTime& start, int index, std::uint32_t data24, int prev_d29, int prev_d30);

  // The data bit (0/1) of the bit on the air during [t, t + 20 ms) (t on a bit edge; t may be a few ns off it),
  // or nothing when unknown. Cheap for increasing t within a subframe (one subframe is cached).
  std::optional<int> bit_at(const signals::GpsTime& t);

  // kDecoded: the signal contradicted the predictions; nothing is known until new subframe 1-3 data arrive.
  void stop();
  bool stopped() const { return stopped_; }
  // True once after add_subframe brought subframe 1-3 data different from the stored ones (cleared by the call).
  bool take_new_data();
  // Nav-file words (subframes 1-3, words 3-10) that agreed / disagreed with the signal's (each word once, and
  // again after a change of mind).
  int nav_words_agreed() const { return nav_words_agreed_; }
  int nav_words_disagreed() const { return nav_words_disagreed_; }

 private:
  void build(const signals::GpsTime& subframe_start);
  void compare_with_nav_file(std::size_t index);
  // The nav file's data words and transmitted bits of the subframe starting at `start` (cached); false when a
  // field does not fit (nothing is then verified).
  bool nav_file_subframe(const signals::GpsTime& start);
  bool issue_of_data_trusted(int subframe_id) const;

  NavBitSource source_;
  std::optional<signals::LnavTransmitter> transmitter_;
  std::optional<std::uint32_t> tlm_;          // word 1 data bits (preamble, TLM message, integrity, reserved)
  std::uint32_t alert_ = 0, anti_spoof_ = 0;  // HOW flags
  struct Stored {
    signals::LnavDataWords words{};
    signals::GpsTime start;
    bool compared = false;  // with the nav file (nav_words_*)
  };
  std::array<std::optional<Stored>, 3> subframes_{};  // latest subframes 1, 2, 3
  bool stopped_ = false, new_data_ = false;
  int nav_words_agreed_ = 0, nav_words_disagreed_ = 0;
  std::array<std::bitset<10>, 3> trusted_{}, rejected_{};  // nav-file words of subframes 1-3, by word index
  signals::GpsTime nav_start_{-1, 0.0};
  bool nav_ok_ = false;
  signals::LnavDataWords nav_data_{};
  signals::SubframeBits nav_bits_{};
  signals::GpsTime cached_start_{-1, 0.0};
  int cached_version_ = -1;
  int version_ = 0;  // bumped by every change of the stored data
  signals::SubframeBits bits_{};
  std::bitset<300> known_;
};

}  // namespace ultratrack::receiver

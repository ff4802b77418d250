// SPDX-License-Identifier: GPL-3.0-or-later
// One channel's navigation-data chain after bit sync: LNAV frame sync and decoding (signals/), plus the
// tie between the channel's code-period count and GPS transmit time. After sync, the code period at which
// the latest subframe began is known together with the GPS time that subframe left the satellite; that
// tag turns a replica code phase into a transmit time, and so into a pseudorange.
#pragma once

#include <array>
#include <cstdint>
#include <optional>

#include "receiver/nav_bit_predictor.hpp"
#include "signals/gps_time.hpp"
#include "signals/lnav_decoder.hpp"
#include "signals/lnav_frame_sync.hpp"

namespace ultratrack::receiver {

// The code period (counted by the channel) at which a subframe's first bit began, and the GPS time at
// which that bit was transmitted.
struct TransmitTimeTag {
  std::int64_t code_period = 0;
  signals::GpsTime transmit_time;
};

class NavigationDataChannel {
 public:
  NavigationDataChannel(int prn, int reference_week);

  // One navigation bit: soft value (its sign is the bit as received: positive = 0) that began at the
  // channel's code period first_code_period. Bits must be consecutive; after a gap call reset().
  void add_bit(float soft, std::int64_t first_code_period);
  // Forget the bit history (after loss of lock or a bit slip); the decoded data are kept.
  void reset();
  // With a time tag every bit's place in its word is known: each word whose parity holds with the two bits before
  // it goes to the bit predictor (NavBitPredictor::add_word), also from subframes that fail or while frame sync
  // is lost, so a nav file's words can be confirmed one by one on a weak signal.

  // While held (the channel coasts on a vector loop's replica, whose code-period count keeps the bit timing),
  // the time tag survives failed subframes and a dropped frame lock; the next good subframe renews it.
  void hold_time_tag(bool hold) {
    if (hold) holding_ = true;
  }
  bool synchronised() const { return (frame_sync_.locked() || holding_) && tag_.has_value(); }
  const std::optional<TransmitTimeTag>& time_tag() const { return tag_; }
  // +1 if the received bits are upright, -1 if inverted (resolves the Costas loop's half-cycle ambiguity).
  int polarity() const { return polarity_; }
  const signals::LnavDecoder& decoder() const { return decoder_; }
  // True once after each subframe that completed a new ephemeris (cleared by the call).
  bool take_new_ephemeris();
  // The bits ahead, from the decoded subframes (and a supplied source, if given one).
  NavBitPredictor& bit_predictor() { return predictor_; }
  const NavBitPredictor& bit_predictor() const { return predictor_; }

 private:
  static constexpr int kHistory = 302;  // a subframe and the two bits before it
  signals::LnavFrameSync frame_sync_;
  signals::LnavDecoder decoder_;
  NavBitPredictor predictor_;
  std::array<std::int64_t, kHistory> code_periods_{};  // code period of each recent bit, by bit index
  std::optional<TransmitTimeTag> tag_;
  int polarity_ = 1;
  bool new_ephemeris_ = false;
  bool holding_ = false;
  void read_word(float soft, std::int64_t first_code_period);
  std::array<std::uint8_t, 32> word_bits_{};  // the latest bits (0/1 as received), oldest first
  int word_fill_ = 0;                         // consecutive bits in word_bits_ (up to 32)
  std::int64_t last_bit_number_ = -2;         // bits since GPS week 0 of the latest bit
};

}  // namespace ultratrack::receiver

// SPDX-License-Identifier: GPL-3.0-or-later
// Frame synchronisation of the 50 bit/s LNAV stream: takes bits one at a time (0/1 as received, either
// polarity) from a channel's bit synchroniser, finds subframe starts by preamble search confirmed with
// the parity of all ten words, then hands over every following 300-bit subframe with its position in the
// bit stream. No allocation; at most one 300-bit parity check per bit while searching.
#pragma once

#include <array>
#include <cstdint>
#include <optional>

#include "signals/lnav_subframe.hpp"

namespace ultratrack::signals {

struct LnavFrameSyncOutput {
  LnavSubframeResult result;         // decoded subframe, or the reason it failed (only while locked)
  std::int64_t first_bit_index = 0;  // index (0 = first bit pushed) of the subframe's first bit
};

class LnavFrameSync {
 public:
  // After this many consecutive failed subframes the lock is dropped and the preamble search restarts.
  static constexpr int kMaxMisses = 2;

  // Pushes one received bit. Returns an output each time a subframe is complete: while searching only a
  // subframe that passes all parity checks (which also establishes lock); once locked, every 300th bit,
  // failures included so that the caller can count them.
  std::optional<LnavFrameSyncOutput> push(std::uint8_t bit);

  bool locked() const { return locked_; }
  std::int64_t bits_pushed() const { return count_; }
  void reset() { *this = LnavFrameSync(); }

 private:
  std::optional<LnavFrameSyncOutput> decode_window();

  std::array<std::uint8_t, 302> window_{};  // last 302 bits, oldest first: 2 previous bits + a subframe
  int filled_ = 0;
  std::int64_t count_ = 0;
  bool locked_ = false;
  int since_start_ = 0;  // bits since the current subframe start while locked
  int misses_ = 0;
};

}  // namespace ultratrack::signals

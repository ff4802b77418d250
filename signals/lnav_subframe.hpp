// SPDX-License-Identifier: GPL-3.0-or-later
// One LNAV subframe read back from 300 received bits (IS-GPS-200 20.3): preamble and polarity, the parity
// of all ten words (20.3.5), the TLM/HOW fields and the 24-bit data words with polarity restored.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <span>

#include "signals/lnav_fields.hpp"

namespace ultratrack::signals {

enum class LnavStatus {
  kOk,
  kNoPreamble,   // bits 1-8 are neither 10001011 nor its complement
  kParityError,  // some word failed its parity check
  kBadHow,       // HOW subframe ID outside 1..5 or TOW count >= 100800
};

struct LnavSubframe {
  LnavDataWords words{};  // d1..d24 of each word, polarity restored (d1 in bit 23)
  int subframe_id = 0;    // 1..5
  int tow_count = 0;      // HOW TOW count: start of the NEXT subframe in 6 s units, 0..100799
  bool alert = false;
  bool anti_spoof = false;
  bool inverted = false;  // the bits were received with inverted polarity
  int page_sv_id = -1;    // subframes 4/5: the page's SV ID (IS-GPS-200 Table 20-V); -1 for 1-3

  // Seconds of week at which this subframe's first bit was transmitted (TOW count x 6 s - 6 s, wrapped).
  double start_tow_s() const;
};

struct LnavSubframeResult {
  LnavStatus status = LnavStatus::kNoPreamble;
  int failed_word = 0;    // kParityError: the first word (1..10) whose parity failed
  LnavSubframe subframe;  // meaningful only when status == kOk
};

// previous_bits: the two bits received just before the subframe (the previous word's D29*, D30*) in the
// received polarity; without them the IS-GPS-200 value 0, 0 (upright) is assumed. Polarity comes from the
// preamble: a complemented preamble means the whole subframe (and previous_bits) is inverted.
LnavSubframeResult decode_lnav_subframe(std::span<const std::uint8_t, 300> bits,
                                        std::optional<std::array<std::uint8_t, 2>> previous_bits = std::nullopt);

}  // namespace ultratrack::signals

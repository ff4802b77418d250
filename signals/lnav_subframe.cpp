// SPDX-License-Identifier: GPL-3.0-or-later
#include "signals/lnav_subframe.hpp"

#include "signals/gps_constants.hpp"
#include "signals/lnav_layout.hpp"
#include "signals/lnav_parity.hpp"

namespace ultratrack::signals {
namespace {

using namespace lnav;

std::uint32_t get(const LnavDataWords& w, Field f) { return get_lnav_field(w, f.first, f.length); }
constexpr std::uint32_t kInvertedPreamble = ~kLnavPreamble & 0xFFu;

}  // namespace

double LnavSubframe::start_tow_s() const {
  const int count = (tow_count + kLnavTowCountModulus - 1) % kLnavTowCountModulus;
  return count * kSubframeDuration_s;
}

LnavSubframeResult decode_lnav_subframe(std::span<const std::uint8_t, 300> bits,
                                        std::optional<std::array<std::uint8_t, 2>> previous_bits) {
  LnavSubframeResult result;
  const std::uint32_t preamble = pack_bits(bits.subspan(0, 8));
  bool inverted = false;
  if (preamble == kInvertedPreamble) {
    inverted = true;
  } else if (preamble != kLnavPreamble) {
    result.status = LnavStatus::kNoPreamble;
    return result;
  }
  const std::uint32_t flip30 = inverted ? 0x3FFFFFFFu : 0u;
  int d29 = 0, d30 = 0;
  if (previous_bits) {
    d29 = ((*previous_bits)[0] & 1) ^ (inverted ? 1 : 0);
    d30 = ((*previous_bits)[1] & 1) ^ (inverted ? 1 : 0);
  }
  LnavSubframe& sf = result.subframe;
  for (int i = 0; i < 10; ++i) {
    const std::uint32_t word = pack_bits(bits.subspan(30 * static_cast<std::size_t>(i), 30)) ^ flip30;
    const auto data = check_word(word, d29, d30);
    if (!data) {
      result.status = LnavStatus::kParityError;
      result.failed_word = i + 1;
      return result;
    }
    sf.words[static_cast<std::size_t>(i)] = *data;
    d29 = static_cast<int>((word >> 1) & 1u);
    d30 = static_cast<int>(word & 1u);
  }
  sf.inverted = inverted;
  sf.tow_count = static_cast<int>(get(sf.words, kTowCount));
  sf.alert = get(sf.words, kAlert) != 0;
  sf.anti_spoof = get(sf.words, kAntiSpoof) != 0;
  sf.subframe_id = static_cast<int>(get(sf.words, kSubframeId));
  if (sf.subframe_id < 1 || sf.subframe_id > 5 || sf.tow_count >= kLnavTowCountModulus) {
    result.status = LnavStatus::kBadHow;
    return result;
  }
  if (sf.subframe_id >= 4) sf.page_sv_id = static_cast<int>(get(sf.words, kPageSvId));
  result.status = LnavStatus::kOk;
  return result;
}

}  // namespace ultratrack::signals

// SPDX-License-Identifier: GPL-3.0-or-later
#include "signals/lnav_parity.hpp"

#include <array>
#include <bit>

namespace ultratrack::signals {
namespace {

// Data-bit masks of Table 20-XIV: entry k lists d_j (j = 1..24, d1 = bit 23) summed into D25+k.
constexpr std::uint32_t mask_of(std::initializer_list<int> js) {
  std::uint32_t m = 0;
  for (int j : js) m |= 1u << (24 - j);
  return m;
}
constexpr std::array<std::uint32_t, 6> kParityMasks = {
    mask_of({1, 2, 3, 5, 6, 10, 11, 12, 13, 14, 17, 18, 20, 23}),
    mask_of({2, 3, 4, 6, 7, 11, 12, 13, 14, 15, 18, 19, 21, 24}),
    mask_of({1, 3, 4, 5, 7, 8, 12, 13, 14, 15, 16, 19, 20, 22}),
    mask_of({2, 4, 5, 6, 8, 9, 13, 14, 15, 16, 17, 20, 21, 23}),
    mask_of({1, 3, 5, 6, 7, 9, 10, 14, 15, 16, 17, 18, 21, 22, 24}),
    mask_of({3, 5, 6, 8, 9, 10, 11, 13, 15, 19, 22, 23, 24}),
};
// Which previous bit enters each equation: D29* for D25, D27, D30; D30* for D26, D28, D29.
constexpr std::array<bool, 6> kUsesD29 = {true, false, true, false, false, true};

}  // namespace

std::uint32_t lnav_parity(std::uint32_t data24, int prev_d29, int prev_d30) {
  std::uint32_t parity = 0;
  for (int k = 0; k < 6; ++k) {
    const std::uint32_t prev = static_cast<std::uint32_t>(kUsesD29[k] ? prev_d29 : prev_d30) & 1u;
    const std::uint32_t bit = prev ^ (static_cast<std::uint32_t>(std::popcount(data24 & kParityMasks[k])) & 1u);
    parity = (parity << 1) | bit;
  }
  return parity;
}

std::uint32_t encode_lnav_word(std::uint32_t data24, int prev_d29, int prev_d30) {
  data24 &= 0xFFFFFFu;
  const std::uint32_t sent = (prev_d30 & 1) ? (~data24 & 0xFFFFFFu) : data24;
  return (sent << 6) | lnav_parity(data24, prev_d29, prev_d30);
}

std::uint32_t solve_lnav_parity_bits(std::uint32_t data24, int prev_d29, int prev_d30) {
  data24 &= 0xFFFFFCu;
  for (std::uint32_t t = 0; t < 4; ++t) {
    if ((lnav_parity(data24 | t, prev_d29, prev_d30) & 3u) == 0) return data24 | t;
  }
  // D29 and D30 depend on d23, d24 through an invertible 2x2 system, so one t always works.
  return data24;
}

std::optional<std::uint32_t> check_word(std::uint32_t word30, int prev_d29, int prev_d30) {
  const std::uint32_t sent = (word30 >> 6) & 0xFFFFFFu;
  const std::uint32_t data24 = (prev_d30 & 1) ? (~sent & 0xFFFFFFu) : sent;
  if (lnav_parity(data24, prev_d29, prev_d30) != (word30 & 0x3Fu)) return std::nullopt;
  return data24;
}

std::optional<std::uint32_t> check_word(std::span<const std::uint8_t, 30> bits, int prev_d29, int prev_d30) {
  return check_word(pack_bits(bits), prev_d29, prev_d30);
}

std::uint32_t pack_bits(std::span<const std::uint8_t> bits) {
  std::uint32_t v = 0;
  for (std::uint8_t b : bits) v = (v << 1) | (b & 1u);
  return v;
}

}  // namespace ultratrack::signals

// SPDX-License-Identifier: GPL-3.0-or-later
// LNAV word parity (IS-GPS-200 20.3.5, Table 20-XIV): the (32,26) extended Hamming code that protects each
// 30-bit word, with the previous word's last two transmitted bits D29*, D30* chained in. Words are held
// right-aligned in a uint32: bit 29 is D1 (first transmitted), bit 0 is D30; data words are 24 bits, d1 = bit 23.
#pragma once

#include <cstdint>
#include <optional>
#include <span>

namespace ultratrack::signals {

// The six parity bits D25..D30 (D25 in bit 5) of source data d1..d24, given the previous word's D29*, D30*.
std::uint32_t lnav_parity(std::uint32_t data24, int prev_d29, int prev_d30);

// The 30 transmitted bits of a word: D1..D24 = d1..d24 complemented when D30* = 1, then the parity.
std::uint32_t encode_lnav_word(std::uint32_t data24, int prev_d29, int prev_d30);

// Words 2 and 10 carry two non-information bits (d23, d24) that the transmitter chooses so that the
// word's own D29 = D30 = 0. data24's two LSBs are ignored; returns data24 with them solved.
std::uint32_t solve_lnav_parity_bits(std::uint32_t data24, int prev_d29, int prev_d30);

// Checks a received 30-bit word against its parity. Returns the 24 source data bits (polarity restored
// with D30*) when all six parity bits agree, nothing otherwise.
std::optional<std::uint32_t> check_word(std::uint32_t word30, int prev_d29, int prev_d30);
// The same for 30 bits given one per element (0/1, first transmitted first).
std::optional<std::uint32_t> check_word(std::span<const std::uint8_t, 30> bits, int prev_d29, int prev_d30);

// Packs n (<= 32) bits given one per element (first = MSB) into an integer.
std::uint32_t pack_bits(std::span<const std::uint8_t> bits);

}  // namespace ultratrack::signals

// SPDX-License-Identifier: GPL-3.0-or-later
// Field access inside the data bits of one LNAV subframe (ten 24-bit words, parity stripped) by the
// subframe bit numbers of IS-GPS-200 Figure 20-1 (bit 1 = first bit of the TLM word, 30 bits per word),
// and the fixed-point scalings of Tables 20-I/20-III/20-VI. Shared by the LNAV transmitter and decoder.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <string_view>

namespace ultratrack::signals {

// Data words 1..10 at index 0..9, each right-aligned 24 bits (d1 in bit 23).
using LnavDataWords = std::array<std::uint32_t, 10>;

// Writes/reads `length` (<= 32) bits whose first (MSB) bit is subframe bit `first_bit` (1-based). The field
// must lie inside the data bits of one word (bits 1-24 of it); split fields use the _split variants.
void put_lnav_field(LnavDataWords& words, int first_bit, int length, std::uint32_t value);
std::uint32_t get_lnav_field(const LnavDataWords& words, int first_bit, int length);
// A field transmitted as an MSB part and an LSB part in different words (e.g. M0: 8 + 24 bits).
void put_lnav_split(LnavDataWords& words, int msb_first, int msb_length, int lsb_first, int lsb_length,
                    std::uint32_t value);
std::uint32_t get_lnav_split(const LnavDataWords& words, int msb_first, int msb_length, int lsb_first, int lsb_length);

// How a value becomes a whole number of LSBs: to nearest (our encoder, and what recovers the RINEX value best),
// or toward zero (a C cast, as some other generators quantise: a different last bit in ~half the fields).
enum class FieldRounding { kNearest, kTowardZero };

// Fixed-point encoding of value (in units of the scale factor 2^scale_log2) to an n-bit two's complement
// or unsigned field. Throws InputError naming `what` when it does not fit.
std::uint32_t lnav_signed(double value, int scale_log2, int bits, std::string_view what,
                          FieldRounding rounding = FieldRounding::kNearest);
std::uint32_t lnav_unsigned(double value, int scale_log2, int bits, std::string_view what,
                            FieldRounding rounding = FieldRounding::kNearest);
// An angle in radians as a two's complement semicircle field, wrapped into [-1, 1) semicircles first.
std::uint32_t lnav_angle(double radians, int scale_log2, int bits, FieldRounding rounding = FieldRounding::kNearest);

// Throws InputError("LNAV encoder", problem): a value that cannot be broadcast.
[[noreturn]] void throw_lnav_encoding_error(const std::string& problem);

double lnav_from_signed(std::uint32_t raw, int scale_log2, int bits);
double lnav_from_unsigned(std::uint32_t raw, int scale_log2);
// Semicircle field to radians (IS-GPS-200 pi).
double lnav_angle_from_signed(std::uint32_t raw, int scale_log2, int bits);

inline constexpr std::uint32_t kLnavPreamble = 0x8B;  // 10001011
inline constexpr int kLnavDataIdNav = 1;              // data ID "01" of subframes 4 and 5
inline constexpr int kLnavTowCountModulus = 100800;   // 17-bit HOW TOW count, 6 s units, per week

}  // namespace ultratrack::signals

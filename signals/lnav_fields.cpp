// SPDX-License-Identifier: GPL-3.0-or-later
#include "signals/lnav_fields.hpp"

#include <fmt/format.h>

#include <cassert>
#include <cmath>
#include <string>

#include "signals/gps_constants.hpp"
#include "signals/input_error.hpp"

namespace ultratrack::signals {
namespace {

// Word index (0-based) and the shift of the field's LSB inside the 24 data bits.
struct Place {
  int word;
  int shift;
};
Place place_of(int first_bit, int length) {
  const int word = (first_bit - 1) / 30;
  const int pos = (first_bit - 1) % 30;  // 0-based position of the MSB inside the word
  assert(length >= 1 && length <= 24 && pos + length <= 24 && word < 10);
  return {word, 24 - pos - length};
}
std::uint32_t low_mask(int bits) { return bits >= 32 ? 0xFFFFFFFFu : ((1u << bits) - 1u); }

}  // namespace

// Out of line so that GCC 12 does not constant-fold InputError's message building into a false -Wrestrict.
[[gnu::noinline]] void throw_lnav_encoding_error(const std::string& problem) {
  throw InputError("LNAV encoder", problem);
}

void put_lnav_field(LnavDataWords& words, int first_bit, int length, std::uint32_t value) {
  const Place p = place_of(first_bit, length);
  const std::uint32_t m = low_mask(length) << p.shift;
  words[p.word] = (words[p.word] & ~m) | ((value << p.shift) & m);
}

std::uint32_t get_lnav_field(const LnavDataWords& words, int first_bit, int length) {
  const Place p = place_of(first_bit, length);
  return (words[p.word] >> p.shift) & low_mask(length);
}

void put_lnav_split(LnavDataWords& words, int msb_first, int msb_length, int lsb_first, int lsb_length,
                    std::uint32_t value) {
  put_lnav_field(words, msb_first, msb_length, (value >> lsb_length) & low_mask(msb_length));
  put_lnav_field(words, lsb_first, lsb_length, value & low_mask(lsb_length));
}

std::uint32_t get_lnav_split(const LnavDataWords& words, int msb_first, int msb_length, int lsb_first, int lsb_length) {
  return (get_lnav_field(words, msb_first, msb_length) << lsb_length) | get_lnav_field(words, lsb_first, lsb_length);
}

namespace {
double quantised(double scaled, FieldRounding rounding) {
  return rounding == FieldRounding::kNearest ? std::nearbyint(scaled) : std::trunc(scaled);
}
}  // namespace

std::uint32_t lnav_signed(double value, int scale_log2, int bits, std::string_view what, FieldRounding rounding) {
  const double scaled = std::ldexp(value, -scale_log2);
  const double half_range = std::ldexp(1.0, bits - 1);
  const double r = quantised(scaled, rounding);
  if (!std::isfinite(scaled) || r < -half_range || r >= half_range) {
    throw_lnav_encoding_error(
        fmt::format("{} = {} does not fit {} signed bits of 2^{}", what, value, bits, scale_log2));
  }
  return static_cast<std::uint32_t>(static_cast<std::int64_t>(r)) & low_mask(bits);
}

std::uint32_t lnav_unsigned(double value, int scale_log2, int bits, std::string_view what, FieldRounding rounding) {
  const double scaled = std::ldexp(value, -scale_log2);
  const double r = quantised(scaled, rounding);
  if (!std::isfinite(scaled) || r < 0.0 || r >= std::ldexp(1.0, bits)) {
    throw_lnav_encoding_error(
        fmt::format("{} = {} does not fit {} unsigned bits of 2^{}", what, value, bits, scale_log2));
  }
  return static_cast<std::uint32_t>(static_cast<std::int64_t>(r));
}

std::uint32_t lnav_angle(double radians, int scale_log2, int bits, FieldRounding rounding) {
  double sc = radians / kPi;
  sc -= 2.0 * std::floor((sc + 1.0) / 2.0);  // [-1, 1)
  const double scaled = std::ldexp(sc, -scale_log2);
  const auto r =
      static_cast<std::int64_t>(rounding == FieldRounding::kNearest ? std::round(scaled) : std::trunc(scaled));
  // +1 semicircle after rounding is the same angle as -1: the mask wraps it.
  return static_cast<std::uint32_t>(r) & low_mask(bits);
}

double lnav_from_signed(std::uint32_t raw, int scale_log2, int bits) {
  std::int64_t v = raw & low_mask(bits);
  if (v >= (std::int64_t{1} << (bits - 1))) v -= (std::int64_t{1} << bits);
  return std::ldexp(static_cast<double>(v), scale_log2);
}

double lnav_from_unsigned(std::uint32_t raw, int scale_log2) {
  return std::ldexp(static_cast<double>(raw), scale_log2);
}

double lnav_angle_from_signed(std::uint32_t raw, int scale_log2, int bits) {
  return lnav_from_signed(raw, scale_log2, bits) * kPi;
}

}  // namespace ultratrack::signals

// SPDX-License-Identifier: GPL-3.0-or-later
#include "signals/sample_format.hpp"

namespace ultratrack::signals {

std::optional<SampleFormat> parse_sample_format(std::string_view name) {
  for (auto f : {SampleFormat::i8, SampleFormat::i16, SampleFormat::f32, SampleFormat::r8, SampleFormat::r16,
                 SampleFormat::r2, SampleFormat::i2})
    if (name == to_string(f)) return f;
  return std::nullopt;
}

std::string_view to_string(SampleFormat format) {
  switch (format) {
    case SampleFormat::i8:
      return "i8";
    case SampleFormat::i16:
      return "i16";
    case SampleFormat::f32:
      return "f32";
    case SampleFormat::r8:
      return "r8";
    case SampleFormat::r16:
      return "r16";
    case SampleFormat::r2:
      return "r2";
    case SampleFormat::i2:
      return "i2";
  }
  return "?";
}

std::string_view sample_format_names() { return "i8, i16, f32, r8, r16, r2, i2"; }

std::optional<TwoBitCoding> parse_two_bit_coding(std::string_view name) {
  for (auto c :
       {TwoBitCoding::twos_complement, TwoBitCoding::sign_magnitude, TwoBitCoding::offset_binary, TwoBitCoding::nt1065})
    if (name == to_string(c)) return c;
  return std::nullopt;
}

std::string_view to_string(TwoBitCoding coding) {
  switch (coding) {
    case TwoBitCoding::twos_complement:
      return "twos";
    case TwoBitCoding::sign_magnitude:
      return "sign-magnitude";
    case TwoBitCoding::offset_binary:
      return "offset-binary";
    case TwoBitCoding::nt1065:
      return "nt1065";
  }
  return "?";
}

std::string_view two_bit_coding_names() { return "twos, sign-magnitude, offset-binary, nt1065"; }

std::optional<BitOrder> parse_bit_order(std::string_view name) {
  if (name == "lsb-first") return BitOrder::lsb_first;
  if (name == "msb-first") return BitOrder::msb_first;
  return std::nullopt;
}

std::string_view to_string(BitOrder order) { return order == BitOrder::lsb_first ? "lsb-first" : "msb-first"; }

std::string_view bit_order_names() { return "lsb-first, msb-first"; }

std::array<int, 4> two_bit_levels(TwoBitCoding coding) {
  switch (coding) {
    case TwoBitCoding::twos_complement:
      return {+1, +3, -3, -1};
    case TwoBitCoding::sign_magnitude:
      return {+1, +3, -1, -3};
    case TwoBitCoding::offset_binary:
      return {-3, -1, +1, +3};
    case TwoBitCoding::nt1065:
      return {-1, +1, -3, +3};
  }
  return {+1, +3, -3, -1};
}

bool is_complex(SampleFormat format) {
  return format == SampleFormat::i8 || format == SampleFormat::i16 || format == SampleFormat::f32 ||
         format == SampleFormat::i2;
}

bool is_two_bit(SampleFormat format) { return format == SampleFormat::r2 || format == SampleFormat::i2; }

std::size_t bits_per_sample(SampleFormat format) {
  switch (format) {
    case SampleFormat::i8:
      return 16;
    case SampleFormat::i16:
      return 32;
    case SampleFormat::f32:
      return 64;
    case SampleFormat::r8:
      return 8;
    case SampleFormat::r16:
      return 16;
    case SampleFormat::r2:
      return 2;
    case SampleFormat::i2:
      return 4;
  }
  return 8;
}

std::size_t bytes_per_sample(SampleFormat format) {
  const std::size_t bits = bits_per_sample(format);
  return bits % 8 == 0 ? bits / 8 : 0;
}

std::size_t samples_per_byte(SampleFormat format) {
  const std::size_t bits = bits_per_sample(format);
  return bits < 8 ? 8 / bits : 0;
}

double full_scale(SampleFormat format) {
  switch (format) {
    case SampleFormat::i8:
    case SampleFormat::r8:
      return 127.0;
    case SampleFormat::i16:
    case SampleFormat::r16:
      return 32767.0;
    case SampleFormat::f32:
      return 1.0;
    case SampleFormat::r2:
    case SampleFormat::i2:
      return 3.0;
  }
  return 1.0;
}

double nominal_rms(SampleFormat format) { return is_two_bit(format) ? 2.0 : full_scale(format) / 4.0; }

}  // namespace ultratrack::signals

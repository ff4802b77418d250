// SPDX-License-Identifier: GPL-3.0-or-later
#include "format_options.hpp"

#include "cli_parse.hpp"
#include "signals/input_error.hpp"

namespace ultratrack::tools {

void add_format_options(CLI::App* cmd, FormatArgs& args) {
  cmd->add_option("--format", args.format,
                  "sample format: i8, i16, f32 (interleaved I/Q: int8, int16 LE, float32), r8, r16 (real int8, "
                  "int16 LE), r2 (real 2-bit packed, 4 samples per byte), i2 (2-bit packed I/Q, 2 pairs per byte, "
                  "I first; --iq-swap for Q first)")
      ->required();
  cmd->add_option(
         "--2bit-coding", args.coding,
         "r2/i2: codes 00 01 10 11 stand for: twos = +1 +3 -3 -1 (GNSS-SDR Two_Bit_Packed, MAX2769 two's "
         "complement), sign-magnitude = +1 +3 -1 -3 (MAX2769/MAX2771, PocketSDR), offset-binary = -3 -1 +1 +3, "
         "nt1065 = -1 +1 -3 +3")
      ->capture_default_str();
  cmd->add_option("--2bit-order", args.order,
                  "r2/i2: first sample of a byte in bits 1:0 (lsb-first, GNSS-SDR default) or in bits 7:6 "
                  "(msb-first, GNSS-SDR big_endian_bytes=true)")
      ->capture_default_str();
}

signals::SampleFormat parse_format(const FormatArgs& args) {
  const auto format = signals::parse_sample_format(args.format);
  if (!format) {
    throw signals::InputError("command line", "--format: unknown sample format '" + args.format + "' (" +
                                                  std::string(signals::sample_format_names()) + ")");
  }
  return *format;
}

signals::TwoBitLayout parse_two_bit_layout(const FormatArgs& args) {
  signals::TwoBitLayout layout;
  const auto coding = signals::parse_two_bit_coding(args.coding);
  if (!coding) {
    throw signals::InputError("command line", "--2bit-coding: unknown coding '" + args.coding + "' (" +
                                                  std::string(signals::two_bit_coding_names()) + ")");
  }
  const auto order = signals::parse_bit_order(args.order);
  if (!order) {
    throw signals::InputError("command line", "--2bit-order: unknown bit order '" + args.order + "' (" +
                                                  std::string(signals::bit_order_names()) + ")");
  }
  layout.coding = *coding;
  layout.order = *order;
  return layout;
}

receiver::SampleSourceOptions parse_sample_source_options(const FormatArgs& format, const std::string& fs,
                                                          const std::string& if_hz, bool iq_swap, bool q_negate) {
  receiver::SampleSourceOptions o;
  o.two_bit = parse_two_bit_layout(format);
  o.fs_hz = parse_double_option("--fs", fs);
  o.if_hz = parse_double_option("--if", if_hz);
  o.iq_swap = iq_swap;
  o.q_negate = q_negate;
  return o;
}

}  // namespace ultratrack::tools

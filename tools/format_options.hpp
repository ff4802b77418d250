// SPDX-License-Identifier: GPL-3.0-or-later
// The sample-format options every command shares (--format, --2bit-coding, --2bit-order), declared and
// parsed in this one place so that names, help and messages stay the same (signals/sample_format.hpp).
#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "receiver/sample_source.hpp"
#include "signals/sample_format.hpp"

namespace ultratrack::tools {

struct FormatArgs {
  std::string format, coding = "twos", order = "lsb-first";
};

// Adds the three options to cmd (--format required) with help that lists every name.
void add_format_options(CLI::App* cmd, FormatArgs& args);
// Parsed values; an unknown name is an InputError("command line", ...) that lists the known ones.
signals::SampleFormat parse_format(const FormatArgs& args);
signals::TwoBitLayout parse_two_bit_layout(const FormatArgs& args);
// The sample source options of a command's --fs, --if (text, parsed as InputErrors), --iq-swap, --q-negate and
// the 2-bit layout; start_sample and int16_gain stay at their defaults.
receiver::SampleSourceOptions parse_sample_source_options(const FormatArgs& format, const std::string& fs,
                                                          const std::string& if_hz, bool iq_swap, bool q_negate);

}  // namespace ultratrack::tools

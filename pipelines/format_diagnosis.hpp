// SPDX-License-Identifier: GPL-3.0-or-later
// Why a recording yields nothing: when the receiver tracks no satellite, the likeliest cause is a sample convention
// the user gave wrong, and the one a receiver can test cheaply is the 2-bit packing (coding and bit order of r2/i2
// files: a wrong one scrambles every sample, yet the level histogram looks right). The first 10 ms are searched
// (FFT acquisition, 10 x 1 ms non-coherent, pfa 1e-3 per PRN) with the layout as given and with every other layout;
// a layout that detects at least 4 satellites, and 3 more than the given one, is named with the flags that select
// it (the most satellites; among as many, the strongest peaks: a bit order read backwards still detects many). I/Q swap
// and Q negation are not diagnosed: they mirror the spectrum, and acquisition finds the satellites either way (at
// mirrored Dopplers), so they cannot be the reason nothing is tracked.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "receiver/sample_source.hpp"
#include "signals/sample_format.hpp"

namespace ultratrack::pipelines {

struct FormatDiagnosis {
  int detected_as_given = 0;
  std::string better_flags;      // e.g. "--2bit-coding sign-magnitude --2bit-order msb-first"; empty: none better
  std::vector<int> better_prns;  // what the better layout detects
};

// Reads the file again from options.start_sample; a file too short for 10 ms, or a format that is not 2-bit, gives
// an empty diagnosis. Throws what SampleSource throws for an unreadable file.
FormatDiagnosis diagnose_sample_format(const std::filesystem::path& input, signals::SampleFormat format,
                                       const receiver::SampleSourceOptions& options);

// " With <flags>, the first 10 ms show N satellites (PRNs ...) against M as given." or "" (for error messages).
std::string to_sentence(const FormatDiagnosis& diagnosis);

}  // namespace ultratrack::pipelines

// SPDX-License-Identifier: GPL-3.0-or-later
// Reading odometer.csv (`t_s,pulses,distance_m`, as sim/simulation_files writes it): one row per counting
// interval ending at t_s, at a constant rate. The reader rejects (io::InputError naming the file and line) a
// missing or other header, an empty file, NaN/inf or malformed fields, time that does not increase, negative,
// fractional or absurd (> 1e15) pulses, a negative distance, and an interval that is not the rate's: the declared
// rate when one is given (fuse config `[odometer] rate_hz`), else the file's first interval (tolerance 1 %).
#pragma once

#include <filesystem>
#include <optional>
#include <vector>

#include "ins/odometer.hpp"

namespace ultratrack::ins {

struct OdometerCsvOptions {
  std::optional<double> rate_hz;  // declared rate [Hz]; empty: the first interval sets it
};

struct OdometerRecord {
  std::vector<OdometerSample> samples;
  double rate_hz = 0.0;  // the rate the rows follow
};

OdometerRecord read_odometer_csv(const std::filesystem::path& file, const OdometerCsvOptions& options = {});

}  // namespace ultratrack::ins

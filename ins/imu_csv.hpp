// SPDX-License-Identifier: GPL-3.0-or-later
// IMU CSV in either of two forms, told apart by the header:
//   increments  `t_s,dtheta_x_rad,dtheta_y_rad,dtheta_z_rad,dv_x_mps,dv_y_mps,dv_z_mps`: one row per interval
//               ending at t_s (what the writer writes, with round-trip precision);
//   rates       `t_s,acc_x_mps2,acc_y_mps2,acc_z_mps2,gyro_x_radps,gyro_y_radps,gyro_z_radps`: samples of specific
//               force and body rate at t_s, as most loggers write them; each interval between two samples becomes
//               an increment by the trapezoidal rule (the first sample only opens the first interval).
// Body frame x forward, y right, z down. The reader rejects any other header, malformed rows, NaN/inf,
// non-increasing time and gaps between rows longer than max_gap_s (InputError naming the file and line).
#pragma once

#include <filesystem>
#include <memory>
#include <span>
#include <vector>

#include "ins/nav_state.hpp"

namespace ultratrack::io {
class AtomicFile;
}

namespace ultratrack::ins {

struct ImuCsvOptions {
  double max_gap_s = 1.0;  // a longer interval between rows is an error (lost data, a logger restart)
};

enum class ImuCsvForm { Increments, Rates };
// The form the file's header names; InputError for a header that is neither.
ImuCsvForm imu_csv_form(const std::filesystem::path& file);

std::vector<ImuIncrement> read_imu_csv(const std::filesystem::path& file, const ImuCsvOptions& options = {});

class ImuCsvWriter {
 public:
  explicit ImuCsvWriter(const std::filesystem::path& file);
  ~ImuCsvWriter();
  void write(const ImuIncrement& inc);
  void commit();

 private:
  std::unique_ptr<io::AtomicFile> out_;
};

void write_imu_csv(const std::filesystem::path& file, std::span<const ImuIncrement> imu);

}  // namespace ultratrack::ins

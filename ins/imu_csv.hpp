// IMU CSV: `t_s,dtheta_x_rad,dtheta_y_rad,dtheta_z_rad,dv_x_mps,dv_y_mps,dv_z_mps`, one row per interval
// ending at t_s, increments in the body frame (x forward, y right, z down). Values are written with
// round-trip precision. Readers reject malformed rows, NaN/inf and non-increasing time (InputError).
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


std::vector<ImuIncrement> read_imu_csv(const std::filesystem::path& file);

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

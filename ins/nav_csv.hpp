// SPDX-License-Identifier: GPL-3.0-or-later
// Navigation / truth CSV:
// `t_s,lat_deg,lon_deg,height_m,vel_n_mps,vel_e_mps,vel_d_mps,roll_deg,pitch_deg,yaw_deg`
// (WGS-84 geodetic position, NED velocity, z-y-x Euler attitude of body to NED). Readers reject malformed
// rows, NaN/inf, out-of-range angles and non-increasing time (InputError naming the file and line).
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

std::vector<NavState> read_nav_csv(const std::filesystem::path& file);

class NavCsvWriter {
 public:
  explicit NavCsvWriter(const std::filesystem::path& file);
  ~NavCsvWriter();
  void write(const NavState& s);
  void commit();

 private:
  std::unique_ptr<io::AtomicFile> out_;
};

void write_nav_csv(const std::filesystem::path& file, std::span<const NavState> states);

}  // namespace ultratrack::ins

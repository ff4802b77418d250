// External GNSS fixes for `ultratrack fuse`: the CSV
// `t_s,lat_deg,lon_deg,height_m,vel_n_mps,vel_e_mps,vel_d_mps,sigma_n_m,sigma_e_m,sigma_d_m`
// (WGS-84 geodetic antenna position, NED velocity, 1-sigma NED position error). The three velocity fields
// may be empty together (position-only fix). t_s is on the IMU file's time line. Strict reader: anything
// malformed, non-finite, out of range or not strictly increasing in time is an InputError with file and line.
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <span>
#include <vector>

namespace ultratrack::tools {

struct GnssCsvRow {
  double t_s = 0.0;
  double lat_rad = 0.0, lon_rad = 0.0, height_m = 0.0;
  bool has_velocity = false;
  Eigen::Vector3d v_n = Eigen::Vector3d::Zero();          // m/s, valid when has_velocity
  Eigen::Vector3d sigma_ned_m = Eigen::Vector3d::Ones();  // 1-sigma north, east, down position error
};

std::vector<GnssCsvRow> read_gnss_csv(const std::filesystem::path& file);

// Writes fixes with round-trip precision (empty velocity fields where has_velocity is false), atomically.
void write_gnss_csv(const std::filesystem::path& file, std::span<const GnssCsvRow> fixes);

}  // namespace ultratrack::tools

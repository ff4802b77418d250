// SPDX-License-Identifier: GPL-3.0-or-later
#include "pipelines/fused_nav_csv.hpp"

#include <fmt/core.h>

#include <cmath>
#include <numbers>
#include <string>

#include "ins/attitude.hpp"
#include "io/atomic_file.hpp"
#include "io/input_error.hpp"
#include "io/numeric_csv.hpp"
#include "io/units.hpp"

namespace ultratrack::pipelines {
namespace {

const std::vector<std::string>& header() {
  static const std::vector<std::string> h{
      "t_s",          "lat_deg",         "lon_deg",         "height_m",       "vel_n_mps",
      "vel_e_mps",    "vel_d_mps",       "roll_deg",        "pitch_deg",      "yaw_deg",
      "sigma_n_m",    "sigma_e_m",       "sigma_d_m",       "sigma_vn_mps",   "sigma_ve_mps",
      "sigma_vd_mps", "sigma_att_n_deg", "sigma_att_e_deg", "sigma_att_d_deg"};
  return h;
}

}  // namespace

FusedNavCsvWriter::FusedNavCsvWriter(const std::filesystem::path& file) : out_(std::make_unique<io::AtomicFile>(file)) {
  std::string h;
  for (const auto& n : header()) h += (h.empty() ? "" : ",") + n;
  out_->write(h + "\n");
}

FusedNavCsvWriter::~FusedNavCsvWriter() = default;

void FusedNavCsvWriter::write(const ins::NavState& s, const NavSigma& g) {
  const ins::EulerAngles e = ins::euler_from_quaternion(s.q_nb);
  out_->write(fmt::format("{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}\n", s.t_s,
                          s.lat_rad / io::kRadPerDeg, s.lon_rad / io::kRadPerDeg, s.height_m, s.v_n.x(), s.v_n.y(),
                          s.v_n.z(), e.roll_rad / io::kRadPerDeg, e.pitch_rad / io::kRadPerDeg,
                          e.yaw_rad / io::kRadPerDeg, g.position_ned_m.x(), g.position_ned_m.y(), g.position_ned_m.z(),
                          g.velocity_ned_mps.x(), g.velocity_ned_mps.y(), g.velocity_ned_mps.z(),
                          g.attitude_ned_rad.x() / io::kRadPerDeg, g.attitude_ned_rad.y() / io::kRadPerDeg,
                          g.attitude_ned_rad.z() / io::kRadPerDeg));
}

void FusedNavCsvWriter::commit() { out_->commit(); }

std::vector<FusedNavRow> read_fused_nav_csv(const std::filesystem::path& file) {
  std::vector<FusedNavRow> rows;
  io::read_numeric_csv(file, "fused navigation file", header(), [&](int line, std::span<const double> v) {
    if (!rows.empty() && !(v[0] > rows.back().nav.t_s))
      throw io::InputError(file.string(), fmt::format("time does not increase (t_s {})", v[0]), line);
    if (std::fabs(v[1]) > 90.0) throw io::InputError(file.string(), "lat_deg outside [-90, 90]", line);
    if (std::fabs(v[8]) > 90.0) throw io::InputError(file.string(), "pitch_deg outside [-90, 90]", line);
    for (int i = 10; i < 19; ++i)
      if (v[i] < 0.0) throw io::InputError(file.string(), "negative sigma", line);
    FusedNavRow r;
    r.nav.t_s = v[0];
    r.nav.lat_rad = v[1] * io::kRadPerDeg;
    r.nav.lon_rad = v[2] * io::kRadPerDeg;
    r.nav.height_m = v[3];
    r.nav.v_n = {v[4], v[5], v[6]};
    r.nav.q_nb = ins::quaternion_from_euler({v[7] * io::kRadPerDeg, v[8] * io::kRadPerDeg, v[9] * io::kRadPerDeg});
    r.sigma.position_ned_m = {v[10], v[11], v[12]};
    r.sigma.velocity_ned_mps = {v[13], v[14], v[15]};
    r.sigma.attitude_ned_rad = Eigen::Vector3d(v[16], v[17], v[18]) * io::kRadPerDeg;
    rows.push_back(r);
  });
  return rows;
}

}  // namespace ultratrack::pipelines

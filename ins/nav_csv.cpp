// SPDX-License-Identifier: GPL-3.0-or-later
#include "ins/nav_csv.hpp"

#include <fmt/core.h>

#include <array>
#include <cmath>
#include <fstream>
#include <numbers>
#include <string>

#include "ins/attitude.hpp"
#include "ins/ins_error.hpp"
#include "io/atomic_file.hpp"
#include "io/numeric_csv.hpp"
#include "io/units.hpp"

namespace ultratrack::ins {
namespace {

const std::vector<std::string>& nav_header() {
  static const std::vector<std::string> h{"t_s",       "lat_deg",   "lon_deg",  "height_m",  "vel_n_mps",
                                          "vel_e_mps", "vel_d_mps", "roll_deg", "pitch_deg", "yaw_deg"};
  return h;
}

}  // namespace

std::vector<NavState> read_nav_csv(const std::filesystem::path& file) {
  std::vector<NavState> out;
  io::read_numeric_csv(file, "navigation file", nav_header(), [&](int line_no, std::span<const double> v) {
    if (!out.empty() && !(v[0] > out.back().t_s))
      throw InputError(file.string(), fmt::format("time does not increase (t_s {})", v[0]), line_no);
    if (std::fabs(v[1]) > 90.0) throw InputError(file.string(), "lat_deg outside [-90, 90]", line_no);
    if (std::fabs(v[2]) > 360.0) throw InputError(file.string(), "lon_deg outside [-360, 360]", line_no);
    if (std::fabs(v[8]) > 90.0) throw InputError(file.string(), "pitch_deg outside [-90, 90]", line_no);
    NavState s;
    s.t_s = v[0];
    s.lat_rad = v[1] * io::kRadPerDeg;
    s.lon_rad = v[2] * io::kRadPerDeg;
    s.height_m = v[3];
    s.v_n = {v[4], v[5], v[6]};
    s.q_nb = quaternion_from_euler({v[7] * io::kRadPerDeg, v[8] * io::kRadPerDeg, v[9] * io::kRadPerDeg});
    out.push_back(s);
  });
  return out;
}

NavCsvWriter::NavCsvWriter(const std::filesystem::path& file) : out_(std::make_unique<io::AtomicFile>(file)) {
  std::string h;
  for (const auto& n : nav_header()) h += (h.empty() ? "" : ",") + n;
  out_->write(h + "\n");
}

NavCsvWriter::~NavCsvWriter() = default;

void NavCsvWriter::write(const NavState& s) {
  const EulerAngles e = euler_from_quaternion(s.q_nb);
  out_->write(fmt::format("{},{},{},{},{},{},{},{},{},{}\n", s.t_s, s.lat_rad / io::kRadPerDeg,
                          s.lon_rad / io::kRadPerDeg, s.height_m, s.v_n.x(), s.v_n.y(), s.v_n.z(),
                          e.roll_rad / io::kRadPerDeg, e.pitch_rad / io::kRadPerDeg, e.yaw_rad / io::kRadPerDeg));
}

void NavCsvWriter::commit() { out_->commit(); }

void write_nav_csv(const std::filesystem::path& file, std::span<const NavState> states) {
  NavCsvWriter w(file);
  for (const auto& s : states) w.write(s);
  w.commit();
}

}  // namespace ultratrack::ins

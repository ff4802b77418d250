// SPDX-License-Identifier: GPL-3.0-or-later
#include "sim/truth_csv.hpp"

#include <fmt/core.h>

#include <array>
#include <cmath>
#include <fstream>
#include <numbers>
#include <string>

#include "ins/attitude.hpp"
#include "ins/ins_error.hpp"
#include "ins/nav_csv.hpp"
#include "io/input_error.hpp"
#include "io/numeric_csv.hpp"
#include "io/open_failure.hpp"
#include "io/units.hpp"

namespace ultratrack::sim {
namespace {

const std::vector<std::string>& simulate_truth_header() {
  static const std::vector<std::string> h{"t_s",       "gps_week",  "tow_s",        "ecef_x_m",        "ecef_y_m",
                                          "ecef_z_m",  "lat_deg",   "lon_deg",      "height_m",        "vel_n_mps",
                                          "vel_e_mps", "vel_d_mps", "clock_bias_m", "clock_drift_mps", "roll_deg",
                                          "pitch_deg", "yaw_deg"};
  return h;
}

}  // namespace

std::vector<ins::NavState> read_truth_csv(const std::filesystem::path& file) {
  const std::string name = file.string();
  {
    // The first non-blank line tells the format: simulate's truth.csv or a plain nav CSV.
    std::ifstream in(file);
    if (!in) throw io::InputError(name, "cannot open the truth file: " + io::open_failure_reason());
    std::string line;
    while (std::getline(in, line) && io::trim(line).empty()) {
    }
    if (io::trim(line).rfind("t_s,gps_week,", 0) != 0) return ins::read_nav_csv(file);
  }
  std::vector<ins::NavState> out;
  double week0 = 0.0, tow0 = 0.0;
  io::read_numeric_csv(file, "truth file", simulate_truth_header(), [&](int line_no, std::span<const double> v) {
    if (out.empty()) {
      week0 = v[1];
      tow0 = v[2];
    }
    const double t_s = (v[1] - week0) * 604800.0 + (v[2] - tow0);
    if (!out.empty() && !(t_s > out.back().t_s))
      throw io::InputError(name, fmt::format("GPS time does not increase (tow_s {})", v[2]), line_no);
    if (std::fabs(v[6]) > 90.0) throw io::InputError(name, "lat_deg outside [-90, 90]", line_no);
    if (std::fabs(v[15]) > 90.0) throw io::InputError(name, "pitch_deg outside [-90, 90]", line_no);
    ins::NavState s;
    s.t_s = t_s;
    s.lat_rad = v[6] * io::kRadPerDeg;
    s.lon_rad = v[7] * io::kRadPerDeg;
    s.height_m = v[8];
    s.v_n = {v[9], v[10], v[11]};
    s.q_nb = ins::quaternion_from_euler({v[14] * io::kRadPerDeg, v[15] * io::kRadPerDeg, v[16] * io::kRadPerDeg});
    out.push_back(s);
  });
  return out;
}

}  // namespace ultratrack::sim

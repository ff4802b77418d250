// SPDX-License-Identifier: GPL-3.0-or-later
#include "pipelines/gps_attitude_csv.hpp"

#include <fmt/core.h>

#include <array>
#include <cmath>
#include <numbers>
#include <span>
#include <string>

#include "io/input_error.hpp"
#include "io/numeric_csv.hpp"
#include "io/units.hpp"
#include "io/whole_number.hpp"

namespace ultratrack::pipelines {
namespace {

constexpr std::size_t kColumns = 11;

const std::vector<std::string>& attitude_header() {
  static const std::vector<std::string> h{"gps_week",       "tow_s",           "roll_deg",      "pitch_deg", "yaw_deg",
                                          "sigma_roll_deg", "sigma_pitch_deg", "sigma_yaw_deg", "num_sats",  "fixed",
                                          "ratio"};
  return h;
}

// A data row's 11 numbers (nan allowed here; the row checks decide where it is acceptable).
std::array<double, kColumns> parse_row(const std::string& file, int line, std::span<const std::string_view> fields) {
  std::array<double, kColumns> v{};
  for (std::size_t i = 0; i < kColumns; ++i) {
    const auto x = io::parse_csv_number(file, line, attitude_header()[i], fields[i]);
    if (!x) throw io::InputError(file, fmt::format("{} is not a number: ''", attitude_header()[i]), line);
    v[i] = *x;
  }
  return v;
}

}  // namespace

std::vector<AttitudeCsvRow> read_attitude_csv(const std::filesystem::path& file) {
  const std::string name = file.string();
  std::vector<AttitudeCsvRow> rows;
  io::read_csv_rows(file, "attitude file", attitude_header(), [&](int line, std::span<const std::string_view> fields) {
    const auto v = parse_row(name, line, fields);
    auto fail = [&](const std::string& what) { throw io::InputError(name, what, line); };
    for (int i : {0, 1, 8, 9, 10})
      if (!std::isfinite(v[static_cast<std::size_t>(i)]))
        fail(attitude_header()[static_cast<std::size_t>(i)] + " is not finite");
    if (!(v[1] >= 0.0 && v[1] < 604800.0)) fail("tow_s outside [0, 604800)");
    if (v[9] != 0.0 && v[9] != 1.0) fail("fixed must be 0 or 1");
    AttitudeCsvRow r;
    r.line = line;
    r.time = signals::GpsTime{io::whole_number_field(v[0], 0, io::kMaxGpsWeek, name, line, "gps_week"), v[1]};
    r.euler = {v[2] * io::kRadPerDeg, v[3] * io::kRadPerDeg, v[4] * io::kRadPerDeg};
    r.sigma_roll_rad = v[5] * io::kRadPerDeg;
    r.sigma_pitch_rad = v[6] * io::kRadPerDeg;
    r.sigma_yaw_rad = v[7] * io::kRadPerDeg;
    r.num_sats = io::whole_number_field(v[8], 0, 999, name, line, "num_sats");
    r.fixed = v[9] == 1.0;
    r.ratio = v[10];
    if (r.fixed) {
      for (std::size_t i = 2; i < 8; ++i)
        if (!std::isfinite(v[i])) fail("fixed row: " + attitude_header()[i] + " is not finite");
      if (std::abs(v[2]) > 180.0 || std::abs(v[3]) > 90.0 || std::abs(v[4]) > 360.0)
        fail("fixed row: angle out of range (roll +-180, pitch +-90, yaw +-360 deg)");
      for (std::size_t i = 5; i < 8; ++i)
        if (!(v[i] > 0.0)) fail("fixed row: " + attitude_header()[i] + " must be positive");
    }
    if (!rows.empty() && !(signals::seconds_between(r.time, rows.back().time) > 0.0))
      fail(fmt::format("time {} {:.4f} not after the previous row's (line {})", r.time.week, r.time.tow_s,
                       rows.back().line));
    rows.push_back(r);
  });
  return rows;
}

}  // namespace ultratrack::pipelines

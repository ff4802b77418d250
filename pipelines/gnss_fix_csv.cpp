// SPDX-License-Identifier: GPL-3.0-or-later
#include "pipelines/gnss_fix_csv.hpp"

#include <fmt/core.h>

#include <array>
#include <cmath>
#include <numbers>
#include <span>
#include <string>

#include "io/atomic_file.hpp"
#include "io/input_error.hpp"
#include "io/numeric_csv.hpp"
#include "io/units.hpp"

namespace ultratrack::pipelines {
namespace {

constexpr int kColumns = 10;

const std::vector<std::string>& gnss_header() {
  static const std::vector<std::string> h{"t_s",       "lat_deg",   "lon_deg",   "height_m",  "vel_n_mps",
                                          "vel_e_mps", "vel_d_mps", "sigma_n_m", "sigma_e_m", "sigma_d_m"};
  return h;
}

// One field: empty -> false; a finite number -> true; anything else throws.
bool parse_field(const std::string& file, int line, int column, std::string_view field, double& out) {
  const auto& name = gnss_header()[static_cast<std::size_t>(column)];
  const auto v = io::parse_csv_number(file, line, name, field);
  if (!v) return false;
  if (!std::isfinite(*v))
    throw io::InputError(file, fmt::format("{} is not finite: '{}'", name, io::trim(field)), line);
  out = *v;
  return true;
}

}  // namespace

std::vector<GnssCsvRow> read_gnss_csv(const std::filesystem::path& file) {
  const std::string name = file.string();
  std::vector<GnssCsvRow> fixes;
  io::read_csv_rows(file, "GNSS file", gnss_header(), [&](int line, std::span<const std::string_view> fields) {
    std::array<double, kColumns> v{};
    std::array<bool, kColumns> present{};
    for (int i = 0; i < kColumns; ++i) present[i] = parse_field(name, line, i, fields[i], v[i]);
    for (int i : {0, 1, 2, 3, 7, 8, 9})
      if (!present[i]) throw io::InputError(name, fmt::format("{} is empty", gnss_header()[i]), line);
    const int n_vel = int(present[4]) + int(present[5]) + int(present[6]);
    if (n_vel != 0 && n_vel != 3)
      throw io::InputError(name, "velocity fields must be all three given or all three empty", line);
    if (std::fabs(v[1]) > 90.0) throw io::InputError(name, "lat_deg outside [-90, 90]", line);
    if (std::fabs(v[2]) > 360.0) throw io::InputError(name, "lon_deg outside [-360, 360]", line);
    if (!(v[3] > -1.0e4 && v[3] < 1.0e8)) throw io::InputError(name, "height_m outside [-10 km, 100000 km]", line);
    for (int i : {7, 8, 9})
      if (!(v[i] > 0.0)) throw io::InputError(name, fmt::format("{} must be positive", gnss_header()[i]), line);
    if (!fixes.empty() && !(v[0] > fixes.back().t_s))
      throw io::InputError(name, fmt::format("time does not increase (t_s {} after {})", v[0], fixes.back().t_s), line);
    GnssCsvRow f;
    f.t_s = v[0];
    f.lat_rad = v[1] * io::kRadPerDeg;
    f.lon_rad = v[2] * io::kRadPerDeg;
    f.height_m = v[3];
    f.has_velocity = n_vel == 3;
    if (f.has_velocity) f.v_n = {v[4], v[5], v[6]};
    f.sigma_ned_m = {v[7], v[8], v[9]};
    fixes.push_back(f);
  });
  return fixes;
}

void write_gnss_csv(const std::filesystem::path& file, std::span<const GnssCsvRow> fixes) {
  io::AtomicFile out(file);
  std::string h;
  for (const auto& c : gnss_header()) h += (h.empty() ? "" : ",") + c;
  out.write(h + "\n");
  for (const auto& f : fixes) {
    const std::string vel =
        f.has_velocity ? fmt::format("{},{},{}", f.v_n.x(), f.v_n.y(), f.v_n.z()) : std::string(",,");
    out.write(fmt::format("{},{},{},{},{},{},{},{}\n", f.t_s, f.lat_rad / io::kRadPerDeg, f.lon_rad / io::kRadPerDeg,
                          f.height_m, vel, f.sigma_ned_m.x(), f.sigma_ned_m.y(), f.sigma_ned_m.z()));
  }
  out.commit();
}

}  // namespace ultratrack::pipelines

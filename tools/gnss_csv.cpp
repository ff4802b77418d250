#include "gnss_csv.hpp"

#include <fmt/core.h>

#include <array>
#include <charconv>
#include <cmath>
#include <fstream>
#include <numbers>
#include <string>

#include "io/atomic_file.hpp"
#include "io/input_error.hpp"
#include "io/numeric_csv.hpp"

namespace ultratrack::tools {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;
constexpr int kColumns = 10;

const std::vector<std::string>& gnss_header() {
  static const std::vector<std::string> h{"t_s",       "lat_deg",   "lon_deg",   "height_m",  "vel_n_mps",
                                          "vel_e_mps", "vel_d_mps", "sigma_n_m", "sigma_e_m", "sigma_d_m"};
  return h;
}

// One field: empty -> false; a finite number -> true; anything else throws.
bool parse_field(const std::string& file, int line, int column, std::string_view field, double& out) {
  field = io::trim(field);
  if (field.empty()) return false;
  const char* first = field.data();
  const char* last = field.data() + field.size();
  if (*first == '+') ++first;
  const auto [ptr, ec] = std::from_chars(first, last, out);
  if (ec != std::errc() || ptr != last)
    throw io::InputError(file, fmt::format("{} is not a number: '{}'", gnss_header()[column], field), line);
  if (!std::isfinite(out))
    throw io::InputError(file, fmt::format("{} is not finite: '{}'", gnss_header()[column], field), line);
  return true;
}

}  // namespace

std::vector<GnssCsvRow> read_gnss_csv(const std::filesystem::path& file) {
  const std::string name = file.string();
  std::ifstream in(file);
  if (!in) throw io::InputError(name, "cannot open GNSS file");
  std::vector<GnssCsvRow> fixes;
  std::string text;
  int line = 0;
  bool have_header = false;
  while (std::getline(in, text)) {
    ++line;
    const std::string_view t = io::trim(text);
    if (t.empty() || t.front() == '#') continue;
    if (!have_header) {
      io::check_csv_header(name, line, t, gnss_header());
      have_header = true;
      continue;
    }
    std::array<std::string_view, kColumns> fields;
    std::string_view rest = t;
    int n = 0;
    while (true) {
      const std::size_t comma = rest.find(',');
      if (n == kColumns) throw io::InputError(name, fmt::format("more than {} fields", kColumns), line);
      fields[n++] = rest.substr(0, comma);
      if (comma == std::string_view::npos) break;
      rest.remove_prefix(comma + 1);
    }
    if (n != kColumns) throw io::InputError(name, fmt::format("expected {} fields, got {}", kColumns, n), line);
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
      throw io::InputError(name, fmt::format("time does not increase (t_s {} after {})", v[0], fixes.back().t_s),
                           line);
    GnssCsvRow f;
    f.t_s = v[0];
    f.lat_rad = v[1] * kDeg;
    f.lon_rad = v[2] * kDeg;
    f.height_m = v[3];
    f.has_velocity = n_vel == 3;
    if (f.has_velocity) f.v_n = {v[4], v[5], v[6]};
    f.sigma_ned_m = {v[7], v[8], v[9]};
    fixes.push_back(f);
  }
  if (!have_header) throw io::InputError(name, "empty GNSS file: missing header");
  if (fixes.empty()) throw io::InputError(name, "GNSS file has no data rows");
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
    out.write(fmt::format("{},{},{},{},{},{},{},{}\n", f.t_s, f.lat_rad / kDeg, f.lon_rad / kDeg, f.height_m, vel,
                          f.sigma_ned_m.x(), f.sigma_ned_m.y(), f.sigma_ned_m.z()));
  }
  out.commit();
}

}  // namespace ultratrack::tools

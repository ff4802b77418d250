// SPDX-License-Identifier: GPL-3.0-or-later
#include "pipelines/pps_time_sync.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "io/input_error.hpp"
#include "io/numeric_csv.hpp"
#include "io/whole_number.hpp"

namespace ultratrack::pipelines {

std::vector<PpsEdge> read_pps_csv(const std::filesystem::path& file) {
  const std::string name = file.string();
  std::vector<PpsEdge> edges;
  io::read_numeric_csv(
      file, "PPS file", {"local_s", "gps_week", "gps_tow_s"}, [&](int line, std::span<const double> v) {
        if (!(v[2] >= 0.0 && v[2] < 604800.0) || std::abs(v[2] - std::round(v[2])) > 1e-6)
          throw io::InputError(name, "gps_tow_s must be a whole second in [0, 604800) (a PPS edge)", line);
        const int week = io::whole_number_field(v[1], 0, io::kMaxGpsWeek, name, line, "gps_week");
        PpsEdge e{line, v[0], {week, std::round(v[2])}};
        if (!edges.empty()) {
          if (!(e.local_s > edges.back().local_s)) throw io::InputError(name, "local_s must increase", line);
          if (!(signals::seconds_between(e.gps, edges.back().gps) > 0.0))
            throw io::InputError(name, "GPS time must increase", line);
        }
        edges.push_back(e);
      });
  return edges;
}

PpsClockFit fit_pps_clock(std::span<const PpsEdge> edges, const std::string& file, const PpsOptions& o) {
  if (edges.size() < 3) throw io::InputError(file, fmt::format("{} PPS edges: at least 3 are needed", edges.size()));
  for (std::size_t i = 1; i < edges.size(); ++i)
    if (edges[i].local_s - edges[i - 1].local_s > o.max_gap_s)
      throw io::InputError(
          file,
          fmt::format("a gap of {:.1f} s between PPS edges (lines {} and {}), more than {} s",
                      edges[i].local_s - edges[i - 1].local_s, edges[i - 1].line, edges[i].line, o.max_gap_s),
          edges[i].line);
  PpsClockFit f;
  f.reference = edges.front().gps;
  f.local_reference_s = edges.front().local_s;
  f.first_local_s = edges.front().local_s;
  f.last_local_s = edges.back().local_s;
  const std::size_t n = edges.size();
  std::vector<double> x(n), y(n), residual(n);
  for (std::size_t i = 0; i < n; ++i) {
    x[i] = edges[i].local_s - f.local_reference_s;
    y[i] = signals::seconds_between(edges[i].gps, f.reference);
  }
  std::vector<bool> use(n, true);
  for (int iteration = 0; iteration < 10; ++iteration) {
    double sx = 0, sy = 0, sxx = 0, sxy = 0, m = 0;
    for (std::size_t i = 0; i < n; ++i) {
      if (!use[i]) continue;
      sx += x[i];
      sy += y[i];
      sxx += x[i] * x[i];
      sxy += x[i] * y[i];
      m += 1;
    }
    const double den = m * sxx - sx * sx;
    if (m < 3 || !(den > 0.0)) throw io::InputError(file, "too few consistent PPS edges to fit the local clock");
    const double slope = (m * sxy - sx * sy) / den;
    f.offset_s = (sy - slope * sx) / m;
    f.drift = slope - 1.0;
    std::vector<double> abs_used;
    for (std::size_t i = 0; i < n; ++i) {
      residual[i] = y[i] - (f.offset_s + slope * x[i]);
      if (use[i]) abs_used.push_back(std::abs(residual[i]));
    }
    std::nth_element(abs_used.begin(), abs_used.begin() + abs_used.size() / 2, abs_used.end());
    const double threshold = std::max(o.outlier_floor_s, 5.0 * 1.4826 * abs_used[abs_used.size() / 2]);
    bool changed = false;
    for (std::size_t i = 0; i < n; ++i) {
      const bool keep = std::abs(residual[i]) <= threshold;
      changed |= keep != use[i];
      use[i] = keep;
    }
    if (!changed) break;
  }
  double ss = 0.0;
  f.used = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (!use[i]) continue;
    ss += residual[i] * residual[i];
    ++f.used;
  }
  f.rejected = static_cast<int>(n) - f.used;
  if (f.used < 3) throw io::InputError(file, "too few consistent PPS edges to fit the local clock");
  f.residual_rms_s = std::sqrt(ss / f.used);
  return f;
}

std::vector<ins::ImuIncrement> imu_on_gps_time(std::span<const ins::ImuIncrement> imu, const PpsClockFit& fit,
                                               const signals::GpsTime& origin, const std::string& imu_file,
                                               const PpsOptions& o) {
  if (!imu.empty() &&
      (imu.front().t_s < fit.first_local_s - o.max_gap_s || imu.back().t_s > fit.last_local_s + o.max_gap_s))
    throw io::InputError(
        imu_file, fmt::format("IMU stamps ({:.3f}-{:.3f} s local) reach beyond the PPS record "
                              "({:.3f}-{:.3f} s local) by more than {} s",
                              imu.front().t_s, imu.back().t_s, fit.first_local_s, fit.last_local_s, o.max_gap_s));
  const double shift = signals::seconds_between(fit.reference, origin);
  std::vector<ins::ImuIncrement> out(imu.begin(), imu.end());
  for (auto& r : out) r.t_s = shift + fit.gps_seconds_since_reference(r.t_s);
  return out;
}

ImuOnPps imu_on_gps_time_by_pps(std::span<const ins::ImuIncrement> imu, const std::string& imu_file,
                                const std::filesystem::path& pps_file, const std::optional<signals::GpsTime>& origin) {
  const std::string name = pps_file.string();
  ImuOnPps r;
  r.fit = fit_pps_clock(read_pps_csv(pps_file), name);
  r.origin = origin.value_or(r.fit.reference);
  r.imu = imu_on_gps_time(imu, r.fit, r.origin, imu_file);
  r.note = fmt::format(
      "IMU local clock on GPS time by {}: {} edges used, {} rejected, drift {:.3f} ppm, "
      "residual RMS {:.2f} us",
      name, r.fit.used, r.fit.rejected, r.fit.drift * 1e6, r.fit.residual_rms_s * 1e6);
  return r;
}

}  // namespace ultratrack::pipelines

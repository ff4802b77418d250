// SPDX-License-Identifier: GPL-3.0-or-later
#include "ins/trajectory.hpp"

#include <cmath>
#include <fstream>
#include <numbers>

#include "ins/ins_error.hpp"
#include "io/numeric_csv.hpp"
#include "io/units.hpp"

namespace ultratrack::ins {
namespace {

// Aircraft roll into and out of turns over 3 s (peak roll rate about 30 deg/s when the S reverses its
// 24 deg bank): realistic, and it keeps the two-sample algorithms' error far below the tolerance.
constexpr double kAircraftRamp_s = 3.0;

}  // namespace

double TrajectorySpec::duration_s() const {
  double d = 0.0;
  for (const auto& s : segments) d += s.duration_s;
  return d;
}

const std::vector<std::string>& profile_names() {
  static const std::vector<std::string> names{"static", "straight", "circle", "s", "spiral", "land"};
  return names;
}

TrajectorySpec profile_spec(std::string_view name, double duration_s, double lat0_rad, double lon0_rad,
                            double height0_m) {
  if (!(duration_s > 0.0) || !std::isfinite(duration_s))
    throw InputError("profile", "duration must be positive, got " + std::to_string(duration_s));
  TrajectorySpec spec;
  spec.lat0_rad = lat0_rad;
  spec.lon0_rad = lon0_rad;
  spec.height0_m = height0_m;
  const double turn = std::numbers::pi / 100.0;
  const double speed_500kmh = 500.0 / 3.6;
  if (name == "static") {
    spec.segments = {{duration_s}};
  } else if (name == "straight") {
    spec.segments = {{duration_s, 1.0}};
  } else if (name == "circle" || name == "spiral") {
    spec.speed0_mps = speed_500kmh;
    spec.ramp_s = kAircraftRamp_s;
    spec.coordinated_turns = true;
    spec.segments = {{duration_s, 0.0, turn, name == "spiral" ? 0.2 : 0.0}};
  } else if (name == "s") {
    spec.speed0_mps = speed_500kmh;
    spec.ramp_s = kAircraftRamp_s;
    spec.coordinated_turns = true;
    double t = 0.0, sign = 1.0;
    while (t < duration_s) {
      const double d = std::min(100.0, duration_s - t);
      spec.segments.push_back({d, 0.0, sign * turn});
      t += d;
      sign = -sign;
    }
  } else if (name == "land") {
    // One cycle (230 s): speeds 0-30 m/s, two stops, right and left turns, a hill up and down.
    const std::vector<Segment> cycle{
        {10.0},                                        // stopped
        {10.0, 2.0},                                   // 0 -> 20 m/s
        {20.0},                                        // cruise
        {20.0, 0.0, 0.0, 0.0, 4.0 * io::kRadPerDeg},   // uphill 4 %
        {20.0, 0.0, 0.0, 0.0, -4.0 * io::kRadPerDeg},  // downhill
        {10.0, -1.0},                                  // 20 -> 10 m/s
        {10.0, 0.0, 9.0 * io::kRadPerDeg},             // 90 deg right turn
        {10.0, 2.0},                                   // 10 -> 30 m/s
        {30.0},                                        // cruise
        {10.0, -3.0},                                  // 30 -> 0 m/s
        {10.0},                                        // stopped
        {10.0, 1.0},                                   // 0 -> 10 m/s
        {15.0, 0.0, -6.0 * io::kRadPerDeg},            // 90 deg left turn
        {25.0, 0.0, 0.0, 0.0, 2.0 * io::kRadPerDeg},   // gentle hill
        {10.0, -1.0},                                  // 10 -> 0 m/s
    };
    double t = 0.0;
    while (t < duration_s) {
      for (const auto& seg : cycle) {
        if (t >= duration_s) break;
        Segment s = seg;
        s.duration_s = std::min(seg.duration_s, duration_s - t);
        spec.segments.push_back(s);
        t += s.duration_s;
      }
    }
  } else {
    std::string known;
    for (const auto& n : profile_names()) known += (known.empty() ? "" : ", ") + n;
    throw InputError("profile", "unknown profile '" + std::string(name) + "' (known: " + known + ")");
  }
  return spec;
}

TrajectorySpec read_segments_csv(const std::filesystem::path& file, const TrajectorySpec& start) {
  TrajectorySpec spec = start;
  spec.segments.clear();
  const std::vector<std::string> header{"duration_s", "accel_mps2", "turn_rate_dps", "climb_rate_mps", "grade_deg"};
  io::read_numeric_csv(file, "segment file", header, [&](int line, std::span<const double> v) {
    if (!(v[0] > 0.0)) throw InputError(file.string(), "segment duration must be positive", line);
    if (std::fabs(v[4]) >= 80.0) throw InputError(file.string(), "grade must be within +-80 deg", line);
    spec.segments.push_back({v[0], v[1], v[2] * io::kRadPerDeg, v[3], v[4] * io::kRadPerDeg});
  });
  return spec;
}

}  // namespace ultratrack::ins

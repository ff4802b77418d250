// SPDX-License-Identifier: GPL-3.0-or-later
#include "sim/scenario.hpp"

#include <fmt/core.h>

#include <cmath>

namespace ultratrack::sim {
namespace {

bool fail(std::string* why, std::string problem) {
  if (why) *why = std::move(problem);
  return false;
}

// The events' antennas exist; events and C/N0 steps need the signal.
bool events_valid(const Scenario& s, std::string* why) {
  const std::size_t antennas = s.antenna_count();
  if ((!s.cycle_slips.empty() || !s.blockages.empty()) && !s.signal)
    return fail(why, "[[cycle_slip]] and [[blockage]] need a [signal] section");
  for (const auto& e : s.cycle_slips)
    if (e.antenna < 0 || static_cast<std::size_t>(e.antenna) >= antennas)
      return fail(why,
                  fmt::format("key cycle_slip.antenna: antenna {} does not exist ({} antennas)", e.antenna, antennas));
  for (const auto& b : s.blockages)
    if (b.antenna < 0 || static_cast<std::size_t>(b.antenna) >= antennas)
      return fail(why,
                  fmt::format("key blockage.antenna: antenna {} does not exist ({} antennas)", b.antenna, antennas));
  if (!s.cn0_steps.empty() && !s.signal) return fail(why, "[[cn0_step]] needs a [signal] section");
  for (const auto& c : s.cn0_steps)
    if (c.antenna < 0 || static_cast<std::size_t>(c.antenna) >= antennas)
      return fail(why,
                  fmt::format("key cn0_step.antenna: antenna {} does not exist ({} antennas)", c.antenna, antennas));
  return true;
}

bool trajectory_valid(const Scenario& s, std::string* why) {
  if (!s.trajectory_profile.empty() && !s.trajectory_file.empty())
    return fail(why, "key trajectory.file: give either profile or file, not both");
  if (!s.trajectory_profile.empty() && !(s.trajectory_duration_s > 0 && s.trajectory_duration_s <= 86400))
    return fail(why, "key trajectory.duration_s: must be within (0, 86400] s (profiles)");
  if (!(s.imu_rate_hz >= 50 && s.imu_rate_hz <= 1000))
    return fail(why, "key trajectory.imu_rate_hz: must be within 50..1000 Hz");
  if (!s.trajectory.empty()) return fail(why, "key receiver.trajectory: not with a [trajectory] section");
  if (std::abs(s.llh_deg_m[0]) >= 89.0)
    return fail(why, "key receiver.llh_deg_m: latitude must be within +-89 deg with [trajectory]");
  if (s.lever_arms_body_m.empty()) return fail(why, "[[antenna]]: an inertial scenario needs at least one antenna");
  return true;
}

}  // namespace

bool Scenario::IsValid(std::string* why) const {
  if (!(sample_rate_hz >= 1e5 && sample_rate_hz <= 1e9))
    return fail(why, "key signal.sample_rate_hz: must be within 100 kHz..1 GHz");
  if (!(duration_s > 0 && duration_s <= 86400)) return fail(why, "key signal.duration_s: must be within (0, 86400] s");
  if (!(cn0_dbhz >= 0 && cn0_dbhz <= 80)) return fail(why, "key signal.cn0_dbhz: must be within 0..80 dB-Hz");
  if (!(truth_rate_hz > 0 && truth_rate_hz <= 1000))
    return fail(why, "key output.truth_rate_hz: must be within (0, 1000] Hz");
  if (!(tow_s >= 0 && tow_s < 604800)) return fail(why, "key time.tow_s: must be within [0, 604800) s");
  if (trajectory_enabled() && !trajectory_valid(*this, why)) return false;
  if (!trajectory_enabled() && antenna_offsets_enu_m.empty())
    return fail(why, "key receiver.antenna_offsets_enu_m: at least one antenna");
  if (!events_valid(*this, why)) return false;
  if (!signals::is_complex(format) && !(if_hz > 0))
    return fail(why,
                "key signal.if_hz: real format " + std::string(signals::to_string(format)) + " needs an IF above 0 Hz");
  if (!(std::abs(if_hz) < 0.5 * sample_rate_hz))
    return fail(why, "key signal.if_hz: must be below half the sample rate");
  return true;
}

std::filesystem::path resolve_path(const Scenario& scenario, const std::string& path) {
  std::filesystem::path p(path);
  if (p.is_absolute() || scenario.source.empty()) return p;
  return scenario.source.parent_path() / p;
}

}  // namespace ultratrack::sim

// SPDX-License-Identifier: GPL-3.0-or-later
// The scenarios of the vector FLL/PLL end-to-end tests and of the pipeline's vector test: 2 MHz i8, 45 dB-Hz, a
// broadcast ephemeris (the shipped brdc3540 file, week 1823) at tow 518772 or, for the tests that need the second
// sky below, at kSecondSkyTow_s; Nagoya, ionosphere on, troposphere off; a static receiver or the 2 g turn step.
#pragma once

#include <filesystem>
#include <fstream>
#include <string>

#include "support/test_data.hpp"

namespace ultratrack::test {

// The second sky: 03:26:12 GPST (12000 s, 400 frames, after 518772; inside the 02:00 records' fit interval). Ten
// satellites at Nagoya, all healthy, 16-81 deg: PRNs 2 (81), 5 (52), 6 (49), 7 (25), 9 (22), 10 (51), 13 (55),
// 26 (31), 29 (16), 30 (24); the count of the shared brdc0010.22n's sky at its 518772 on which these tests were first
// set (ten healthy, 9-69 deg). At 518772 the shipped file shows 12, PRNs 1 and 2 in the 10-17 deg band.
inline constexpr double kSecondSkyTow_s = 530772.0;

// The scenario TOML (the trajectory section appended as given; "" for a static receiver at height_m).
inline std::string vector_carrier_scenario(const std::filesystem::path& brdc, double height_m, double duration_s,
                                           const std::string& trajectory, double tow_s = 518772.0) {
  return "[signal]\nsample_rate_hz = 2.0e6\nformat = \"i8\"\nduration_s = " + std::to_string(duration_s) +
         "\ncn0_dbhz = 45.0\nseed = 4\n[time]\ngps_week = " + std::to_string(shipped_nav_week) +
         "\ntow_s = " + std::to_string(tow_s) + "\n[navigation]\nrinex = \"" + brdc.generic_string() +
         "\"\n[receiver]\nllh_deg_m = [35.274016, 137.013759, " + std::to_string(height_m) +
         "]\n[atmosphere]\nionosphere = true\ntroposphere = false\n" + trajectory;
}

// The 2 g turn step: 139 m/s north, a 8.09 deg/s turn entered at 15 s and held (up to 19.6 m/s^2, 103 Hz/s on a
// line of sight). Writes dir/turn.csv and dir/turn.toml (20 s at 1000 m); returns the TOML's path.
inline std::filesystem::path write_two_g_turn_scenario(const std::filesystem::path& dir,
                                                       const std::filesystem::path& brdc, double tow_s = 518772.0) {
  std::ofstream(dir / "turn.csv") << "duration_s,accel_mps2,turn_rate_dps,climb_rate_mps,grade_deg\n"
                                     "15.0,0.0,0.0,0.0,0.0\n5.0,0.0,8.09,0.0,0.0\n";
  std::ofstream(dir / "turn.toml") << vector_carrier_scenario(
      brdc, 1000.0, 20.0, "[trajectory]\nfile = \"turn.csv\"\nspeed_mps = 138.9\nheading_deg = 0.0\n", tow_s);
  return dir / "turn.toml";
}

}  // namespace ultratrack::test

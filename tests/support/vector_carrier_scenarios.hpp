// SPDX-License-Identifier: GPL-3.0-or-later
// The scenarios of the vector FLL/PLL end-to-end tests and of the pipeline's vector test: 2 MHz i8, 45 dB-Hz, a
// broadcast ephemeris at tow 518772 (the shipped brdc3540 file, week 1823, or the shared brdc0010.22n, week 2190),
// Nagoya, ionosphere on, troposphere off; a static receiver or the 2 g turn step trajectory.
#pragma once

#include <filesystem>
#include <fstream>
#include <string>

#include "support/test_data.hpp"

namespace ultratrack::test {

// The scenario TOML (the trajectory section appended as given; "" for a static receiver at height_m). gps_week:
// the shipped ephemeris's week, or 2190 for the shared brdc0010.22n.
inline std::string vector_carrier_scenario(const std::filesystem::path& brdc, double height_m, double duration_s,
                                           const std::string& trajectory, int gps_week = shipped_nav_week) {
  return "[signal]\nsample_rate_hz = 2.0e6\nformat = \"i8\"\nduration_s = " + std::to_string(duration_s) +
         "\ncn0_dbhz = 45.0\nseed = 4\n[time]\ngps_week = " + std::to_string(gps_week) +
         "\ntow_s = 518772.0\n[navigation]\nrinex = \"" + brdc.generic_string() +
         "\"\n[receiver]\nllh_deg_m = [35.274016, 137.013759, " + std::to_string(height_m) +
         "]\n[atmosphere]\nionosphere = true\ntroposphere = false\n" + trajectory;
}

// The 2 g turn step: 139 m/s north, a 8.09 deg/s turn entered at 15 s and held (up to 19.6 m/s^2, 103 Hz/s on a
// line of sight). Writes dir/turn.csv and dir/turn.toml (20 s at 1000 m); returns the TOML's path.
inline std::filesystem::path write_two_g_turn_scenario(const std::filesystem::path& dir,
                                                       const std::filesystem::path& brdc,
                                                       int gps_week = shipped_nav_week) {
  std::ofstream(dir / "turn.csv") << "duration_s,accel_mps2,turn_rate_dps,climb_rate_mps,grade_deg\n"
                                     "15.0,0.0,0.0,0.0,0.0\n5.0,0.0,8.09,0.0,0.0\n";
  std::ofstream(dir / "turn.toml") << vector_carrier_scenario(
      brdc, 1000.0, 20.0, "[trajectory]\nfile = \"turn.csv\"\nspeed_mps = 138.9\nheading_deg = 0.0\n", gps_week);
  return dir / "turn.toml";
}

}  // namespace ultratrack::test

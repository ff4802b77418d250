// SPDX-License-Identifier: GPL-3.0-or-later
// The ultra-tight tunnel scenario of the end-to-end tests (tests/pipelines/receive_ultratight_test.cpp and the command
// line's, tests/tools/receive_ultratight_cli_test.cpp): 21 s of a car on a 100 m circle at 30 km/h, 45 dB-Hz, 2 MHz
// i8, the shipped ephemeris from TOW 518476 (week 1823), HG1700AE IMU at 100 Hz, every signal absent from 14 to 18 s;
// and the same circle with other settings (write_circle_scenario: the clock-loop test's TCXO and C/N0 step).
#pragma once

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace ultratrack::test {

inline constexpr double kGapStart_s = 14.0, kGapEnd_s = 18.0, kDuration_s = 21.0;
inline constexpr double kStartTow_s = 518476.0;  // the scenario's [time] tow_s (week 1823)

// Writes dir/<stem>.csv and dir/<stem>.toml: the car on the 100 m circle at 30 km/h for duration_s, 45 dB-Hz, 2 MHz
// i8, the ephemeris file brdc from TOW 518476, HG1700AE IMU; receiver_keys are added to its [receiver] table (e.g. an
// oscillator) and tables after the rest (e.g. [[blockage]], [[cn0_step]]).
inline std::filesystem::path write_circle_scenario(const std::filesystem::path& dir, const std::filesystem::path& brdc,
                                                   const std::string& stem, double duration_s, int seed,
                                                   const std::string& receiver_keys, const std::string& tables) {
  std::ofstream(dir / (stem + ".csv")) << "duration_s,accel_mps2,turn_rate_dps,climb_rate_mps,grade_deg\n"
                                       << duration_s << ",0.0,4.774648,0.0,0.0\n";  // v / R = 8.3333 / 100 rad/s
  std::ofstream(dir / (stem + ".toml"))
      << "[signal]\nsample_rate_hz = 2.0e6\nformat = \"i8\"\nduration_s = " << duration_s
      << "\ncn0_dbhz = 45.0\nseed = " << seed << "\n[time]\ngps_week = 1823\ntow_s = 518476.0\n[navigation]\nrinex = \""
      << brdc.generic_string() << "\"\n[receiver]\nllh_deg_m = [35.274016, 137.013759, 100.0]\n"
      << receiver_keys << "[trajectory]\nfile = \"" << stem
      << ".csv\"\nspeed_mps = 8.333333333\nheading_deg = 0.0\nimu_rate_hz = 100.0\n"
         "[imu]\npreset = \"hg1700ae\"\nseed = 7\n[atmosphere]\nionosphere = true\ntroposphere = true\n"
      << tables;
  return dir / (stem + ".toml");
}

// Writes dir/circle.csv and dir/circle.toml (the scenario; brdc: the ephemeris file it names).
inline void write_tunnel_scenario(const std::filesystem::path& dir, const std::filesystem::path& brdc) {
  std::ostringstream blockage;
  blockage << "[[blockage]]\nantenna = 0\nstart_s = " << kGapStart_s << "\nduration_s = " << kGapEnd_s - kGapStart_s
           << "\n";
  write_circle_scenario(dir, brdc, "circle", kDuration_s, 4, "", blockage.str());
}

}  // namespace ultratrack::test

// SPDX-License-Identifier: GPL-3.0-or-later
// The land-vehicle scenario of the GNSS/INS-from-IF end-to-end tests (tests/pipelines/receive_fusion_test.cpp and the
// command line's, tests/tools/receive_fusion_cli_test.cpp): 16 s of a car on a 100 m circle at 30 km/h, HG1700AE
// IMU at 100 Hz, nominal constellation, 2.0 MHz i8 at 45 dB-Hz, from TOW 518776 (first fix ~8.1 s in).
#pragma once

#include <filesystem>
#include <fstream>

namespace ultratrack::test {

inline constexpr double kFusionStartTow_s = 518776.0;  // subframe 518778-518784 arrives at 2.07-8.07 s
inline constexpr double kFusionDuration_s = 16.0;

// Writes dir/circle.csv and dir/circle.toml.
inline void write_fusion_circle_scenario(const std::filesystem::path& dir) {
  std::ofstream(dir / "circle.csv") << "duration_s,accel_mps2,turn_rate_dps,climb_rate_mps,grade_deg\n"
                                       "16.0,0.0,4.774648,0.0,0.0\n";  // v / R = 8.3333 / 100 rad/s
  std::ofstream(dir / "circle.toml")
      << "[signal]\nsample_rate_hz = 2.0e6\nformat = \"i8\"\nduration_s = " << kFusionDuration_s
      << "\ncn0_dbhz = 45.0\nseed = 4\n[time]\ngps_week = 2190\ntow_s = " << kFusionStartTow_s
      << "\n[navigation]\nconstellation = \"nominal\"\n[receiver]\nllh_deg_m = [35.274016, 137.013759, 100.0]\n"
         "[trajectory]\nfile = \"circle.csv\"\nspeed_mps = 8.333333333\nheading_deg = 0.0\nimu_rate_hz = 100.0\n"
         "[imu]\npreset = \"hg1700ae\"\nseed = 7\n[atmosphere]\nionosphere = true\ntroposphere = true\n";
}

}  // namespace ultratrack::test

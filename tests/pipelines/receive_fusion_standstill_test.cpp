// SPDX-License-Identifier: GPL-3.0-or-later
// A MEMS unit parked before it moves, from IF samples through the library (receive --imu, loose, in-motion
// alignment): 22 s of a car parked for 9 s, then accelerating to 7.5 m/s and driving straight, with a BMI088-class
// IMU (1 deg/s turn-on gyro biases) at 100 Hz, nominal constellation, 2.0 MHz i8 at 45 dB-Hz, a hot start from the
// scenario's own ephemerides. The filter, told only the preset class, must measure the gyro biases over the parked
// start (pipelines::motion_standstill in the coupler): the alignment note names them, and each is within 4 of its
// stated 1-sigma (about 20 deg/h) of the unit's simulated turn-on bias. What that buys on a longer drive:
// benchmarks/validation/standstill_if.sh (yaw 0.02 deg RMS against 1.8 learnt in motion).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <regex>
#include <string>

#include "config/scenario_toml.hpp"
#include "ins/imu_csv.hpp"
#include "pipelines/receive_file.hpp"
#include "signals/rinex_nav.hpp"
#include "sim/navigation_source.hpp"
#include "sim/simulation_files.hpp"
#include "support/test_data.hpp"

namespace fs = std::filesystem;
using namespace ultratrack;

namespace {

constexpr double kDegPerHour = 3.14159265358979323846 / 180.0 / 3600.0;  // rad/s

}  // namespace

TEST(ReceiveFusionStandstill, AParkedStartGivesTheGyroBiasesToTheInMotionAlignment) {
  const fs::path dir = test::scratch_dir();
  std::ofstream(dir / "parked.csv") << "duration_s,accel_mps2,turn_rate_dps,climb_rate_mps,grade_deg\n"
                                       "9.0,0.0,0.0,0.0,0.0\n3.0,2.5,0.0,0.0,0.0\n10.0,0.0,0.0,0.0,0.0\n";
  std::ofstream(dir / "parked.toml")
      << "[signal]\nsample_rate_hz = 2.0e6\nformat = \"i8\"\nduration_s = 22.0\ncn0_dbhz = 45.0\nseed = 4\n"
         "[time]\ngps_week = 2190\ntow_s = 518776.0\n[navigation]\nconstellation = \"nominal\"\n"
         "[receiver]\nllh_deg_m = [35.274016, 137.013759, 100.0]\n[trajectory]\nfile = \"parked.csv\"\n"
         "speed_mps = 0.0\nheading_deg = 30.0\nimu_rate_hz = 100.0\n[imu]\npreset = \"bmi088\"\nseed = 7\n";
  const sim::Scenario scenario = config::read_scenario(dir / "parked.toml");
  const sim::SimulationResult simulated = sim::simulate_to_folder(scenario, dir / "sim", "");
  const sim::NavigationSource nav = sim::load_navigation(scenario);
  signals::RinexNavData data;
  data.ephemerides = nav.ephemerides;
  data.klobuchar = nav.klobuchar;
  data.utc = nav.utc;
  signals::write_rinex_nav_304(dir / "nominal.rnx", data);

  pipelines::ReceiveFileJob job;
  job.input = dir / "sim" / "antenna0.i8.bin";
  job.out = dir / "rx";
  job.source.fs_hz = job.options.receiver.fs_hz = 2.0e6;
  job.navigation = signals::read_rinex_nav(dir / "nominal.rnx");
  pipelines::date_recording(job.options.receiver, job.navigation, 0);
  job.imu = ins::read_imu_csv(dir / "sim" / "imu.csv");
  job.options.coupling = pipelines::Coupling::kLoose;
  job.options.align = pipelines::AlignMode::Motion;
  job.options.navigation.imu_preset = "bmi088";
  job.options.navigation.motion_window_s = 1.0;
  pipelines::receive_file(std::move(job));

  const std::string summary = test::read_text_file(dir / "rx" / "summary.json");
  std::smatch m;
  const std::regex note(
      R"(gyro biases from a standstill over ([0-9.]+)-([0-9.]+) s: (-?\d+) (-?\d+) (-?\d+) \+- (\d+) deg/h)");
  ASSERT_TRUE(std::regex_search(summary, m, note)) << summary.substr(0, 2000);
  std::printf("standstill %s-%s s: %s %s %s +- %s deg/h; simulated %.0f %.0f %.0f\n", m[1].str().c_str(),
              m[2].str().c_str(), m[3].str().c_str(), m[4].str().c_str(), m[5].str().c_str(), m[6].str().c_str(),
              simulated.imu_turn_on.gyro.bias.x() / kDegPerHour, simulated.imu_turn_on.gyro.bias.y() / kDegPerHour,
              simulated.imu_turn_on.gyro.bias.z() / kDegPerHour);
  EXPECT_NEAR(std::stod(m[2].str()), 8.0, 1.0 + 1e-9);  // parked until 9 s, the last window the margin
  const double sigma_dph = std::stod(m[6].str());
  EXPECT_LT(sigma_dph, 3600.0 / 30.0);  // the datasheet's turn-on sigma is 3600 deg/h
  for (int axis = 0; axis < 3; ++axis)
    EXPECT_LT(std::fabs(std::stod(m[3 + axis].str()) - simulated.imu_turn_on.gyro.bias[axis] / kDegPerHour),
              4.0 * sigma_dph + 1.0)  // +1: the note's rounding to whole deg/h
        << "axis " << axis;
}

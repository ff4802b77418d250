// SPDX-License-Identifier: GPL-3.0-or-later
// `ultratrack simulate` then `ultratrack attitude` on a short static 3-antenna scenario ([KimAlign]/003 geometry,
// 3 mm phase noise per antenna, 45 dB-Hz, line biases, the shipped 2014-12-20 broadcast ephemeris as hot start),
// checked against the scenario's set attitude: the attitude must be fixed, its errors within the solver's own
// sigma, and the files as documented. The long runs (100 s static, moving, faults) are in docs/validation.md.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "commands.hpp"
#include "run_command.hpp"
#include "signals/input_error.hpp"
#include "support/test_data.hpp"

namespace fs = std::filesystem;

namespace {

void run(const std::string& command, std::vector<std::string> args) {
  ultratrack::test_support::run_command(command, std::move(args), /*quiet=*/false);
}

std::string read(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

double json_number(const std::string& json, const std::string& key) {
  const auto at = json.find("\"" + key + "\":");
  if (at == std::string::npos) return NAN;
  return std::stod(json.substr(at + key.size() + 3));
}

const char* kAntennas = R"(
[[antenna]]
lever_arm_body_m = [0.0, 0.0, 0.0]
[[antenna]]
lever_arm_body_m = [1.0, 0.0, 0.0]
[[antenna]]
lever_arm_body_m = [0.0, 1.025, 0.0]
[solver]
phase_sigma_m = 0.003
elevation_mask_deg = 5.0
)";

}  // namespace

TEST(AttitudeCommand, StaticArrayGivesTheSetAttitude) {
  const std::filesystem::path nav = ultratrack::test::shipped_nav_file();
  const fs::path dir = ultratrack::test::scratch_dir() / "attitude_command";
  fs::create_directories(dir);
  const double roll = 2.0, pitch = -3.0, yaw = 35.0;
  {
    std::ofstream s(dir / "scenario.toml");
    s << "[signal]\nsample_rate_hz = 2.6e6\nformat = \"i8\"\nduration_s = 14.0\ncn0_dbhz = 45.0\nseed = 3\n"
      << "[time]\ngps_week = 1823\ntow_s = 518396.0\n"
      << "[navigation]\nrinex = \"" << nav.string() << "\"\n"
      << "[receiver]\nllh_deg_m = [35.274016, 137.013759, 100.0]\nattitude_deg = [" << roll << ", " << pitch << ", "
      << yaw << "]\n"
      << "[trajectory]\nprofile = \"static\"\nduration_s = 14.0\n"
      << "[[antenna]]\nlever_arm_body_m = [0.0, 0.0, 0.0]\nphase_noise_m = 0.003\n"
      << "[[antenna]]\nlever_arm_body_m = [1.0, 0.0, 0.0]\nphase_noise_m = 0.003\nline_bias_cycles = 0.23\n"
      << "[[antenna]]\nlever_arm_body_m = [0.0, 1.025, 0.0]\nphase_noise_m = 0.003\nline_bias_cycles = -0.41\n";
    std::ofstream(dir / "antennas.toml") << kAntennas;
  }
  run("simulate", {"--scenario", (dir / "scenario.toml").string(), "--out", (dir / "sim").string()});
  const fs::path out = dir / "rx";
  run("attitude", {"--input", (dir / "sim/antenna0.i8.bin").string(), (dir / "sim/antenna1.i8.bin").string(),
                   (dir / "sim/antenna2.i8.bin").string(), "--format", "i8", "--fs", "2.6e6", "--antennas",
                   (dir / "antennas.toml").string(), "--nav", nav.string(), "--out", out.string(), "--quiet"});
  ASSERT_TRUE(fs::exists(out / "position/solution.csv"));
  ASSERT_TRUE(fs::exists(out / "antenna_phases.csv"));
  std::ifstream in(out / "attitude.csv");
  std::string line;
  std::getline(in, line);
  ASSERT_EQ(line,
            "gps_week,tow_s,roll_deg,pitch_deg,yaw_deg,sigma_roll_deg,sigma_pitch_deg,sigma_yaw_deg,num_sats,fixed,"
            "ratio");
  int epochs = 0, fixed = 0, beyond_4_sigma = 0;
  double sq[3] = {0, 0, 0};
  const double truth[3] = {roll, pitch, yaw};
  while (std::getline(in, line)) {
    std::vector<std::string> f;
    std::stringstream ss(line);
    for (std::string item; std::getline(ss, item, ',');) f.push_back(item);
    ASSERT_EQ(f.size(), 11u) << line;
    ++epochs;
    if (f[9] != "1") continue;
    ++fixed;
    EXPECT_GE(std::stoi(f[8]), 8) << "12 satellites above 5 deg in this sky (PRN 12 at 5.0-5.1 deg)";
    for (int i = 0; i < 3; ++i) {
      double e = std::stod(f[2 + i]) - truth[i];
      e -= 360.0 * std::round(e / 360.0);
      sq[i] += e * e;
      beyond_4_sigma += std::abs(e) > 4.0 * std::stod(f[5 + i]);
    }
  }
  // Time tags from ~10 s (the first subframe that completes after bit sync): ~40 epochs at 10 Hz.
  ASSERT_GE(epochs, 30);
  EXPECT_GE(fixed, epochs - 1);
  EXPECT_EQ(beyond_4_sigma, 0);
  // Targets of the issue (yaw 0.15 deg, roll/pitch 0.4 deg RMS); with 10-12 satellites the solver's sigma is
  // ~0.09 deg in yaw and ~0.26 deg in roll/pitch, so the RMS of ~40 epochs sits inside them (this sky: 0.08 yaw,
  // 0.32 roll and pitch).
  const double rms_roll = std::sqrt(sq[0] / fixed), rms_pitch = std::sqrt(sq[1] / fixed),
               rms_yaw = std::sqrt(sq[2] / fixed);
  EXPECT_LT(rms_yaw, 0.15);
  EXPECT_LT(rms_roll, 0.4);
  EXPECT_LT(rms_pitch, 0.4);
  std::printf("[ figures  ] %d epochs, %d fixed; RMS roll %.3f pitch %.3f yaw %.3f deg\n", epochs, fixed, rms_roll,
              rms_pitch, rms_yaw);
  const std::string summary = read(out / "summary.json");
  EXPECT_NEAR(json_number(summary, "fix_rate"), static_cast<double>(fixed) / epochs, 1e-3);
  const double first = json_number(summary, "time_to_first_attitude_s");
  EXPECT_GT(first, 4.0);
  EXPECT_LT(first, 12.0);
  EXPECT_GT(json_number(summary, "realtime_factor"), 0.0);
}

TEST(AttitudeCommand, InputCountMustMatchTheAntennaFile) {
  const fs::path dir = ultratrack::test::scratch_dir() / "attitude_command_errors";
  fs::create_directories(dir);
  std::ofstream(dir / "antennas.toml") << kAntennas;
  std::ofstream(dir / "a.bin", std::ios::binary) << std::string(100, '\0');
  EXPECT_THROW(run("attitude", {"--input", (dir / "a.bin").string(), (dir / "a.bin").string(), "--format", "i8", "--fs",
                                "2.6e6", "--antennas", (dir / "antennas.toml").string(), "--reference-week", "2190",
                                "--out", (dir / "rx").string()}),
               ultratrack::signals::InputError);
  std::ofstream(dir / "bad.toml") << "[[antenna]]\nlever_arm_body_m = [0.0, 0.0, 0.0]\ncable = 3\n";
  try {
    run("attitude",
        {"--input", (dir / "a.bin").string(), (dir / "a.bin").string(), "--format", "i8", "--fs", "2.6e6", "--antennas",
         (dir / "bad.toml").string(), "--reference-week", "2190", "--out", (dir / "rx").string()});
    FAIL() << "no error";
  } catch (const ultratrack::signals::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("antenna.cable"), std::string::npos) << e.what();
  }
}

// SPDX-License-Identifier: GPL-3.0-or-later
// `ultratrack imusim` and `ultratrack ins` end to end, in process: simulated files navigate back onto their
// own truth; coarse alignment mode runs from the stationary start; bad input is a typed error.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "commands.hpp"
#include "ins/ins_error.hpp"
#include "ins/nav_csv.hpp"
#include "run_command.hpp"
#include "support/test_data.hpp"

namespace fs = std::filesystem;

namespace {

void run(const std::vector<std::string>& args) { ultratrack::test_support::run_program(args); }

double json_number(const fs::path& file, const std::string& key) {
  std::ifstream in(file);
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string text = ss.str();
  std::smatch m;
  if (!std::regex_search(text, m, std::regex("\"" + key + "\": ([-+0-9.eE]+)"))) {
    ADD_FAILURE() << key << " missing in " << file;
    return 1e300;
  }
  return std::stod(m[1]);
}

}  // namespace

TEST(InsCommands, SimulatedSpiralNavigatesOntoItsTruth) {
  const fs::path dir = ultratrack::test::scratch_dir();
  run({"imusim", "--profile", "spiral", "--duration", "120", "--rate", "100", "--out", (dir / "sim").string()});
  run({"ins", "--imu", (dir / "sim/imu.csv").string(), "--init", (dir / "sim/truth.csv").string(), "--out",
       (dir / "nav").string()});
  const fs::path summary = dir / "nav/summary.json";
  EXPECT_EQ(json_number(summary, "rows_matched"), 12001);
  EXPECT_LT(json_number(summary, "max_horizontal_error_m"), 1.0);
  EXPECT_LT(json_number(summary, "max_vertical_error_m"), 1.0);
  EXPECT_LT(json_number(summary, "max_attitude_error_deg"), 1e-4);
  EXPECT_EQ(ultratrack::ins::read_nav_csv(dir / "nav/nav.csv").size(), 12001u);
}

// The truth.csv of an inertial `simulate` scenario (IMU only) initialises `ins` and is compared on GPS time.
TEST(InsCommands, SimulateScenarioImuNavigatesOntoItsTruth) {
  const fs::path dir = ultratrack::test::scratch_dir();
  std::ofstream(dir / "s.toml") << "[time]\ngps_week = 2190\ntow_s = 604790.0\n"  // crosses the week
                                   "[receiver]\nllh_deg_m = [36.37, 127.36, 300.0]\n"
                                   "[trajectory]\nprofile = \"spiral\"\nduration_s = 60.0\n[imu]\npreset = \"ideal\"\n";
  run({"simulate", "--scenario", (dir / "s.toml").string(), "--out", (dir / "sim").string(), "--quiet"});
  run({"ins", "--imu", (dir / "sim/imu.csv").string(), "--init", (dir / "sim/truth.csv").string(), "--out",
       (dir / "nav").string()});
  const fs::path summary = dir / "nav/summary.json";
  EXPECT_EQ(json_number(summary, "rows_matched"), 601);  // every 10 Hz truth row
  EXPECT_LT(json_number(summary, "max_horizontal_error_m"), 1.0);
  EXPECT_LT(json_number(summary, "max_vertical_error_m"), 1.0);
  EXPECT_LT(json_number(summary, "max_attitude_error_deg"), 1e-4);
}

TEST(InsCommands, AlignModeLevelsFromStationaryData) {
  const fs::path dir = ultratrack::test::scratch_dir();
  run({"imusim", "--profile", "static", "--duration", "120", "--preset", "navigation", "--seed", "4", "--out",
       (dir / "sim").string()});
  run({"ins", "--imu", (dir / "sim/imu.csv").string(), "--align", "60", "--position", "36.37", "127.36", "100",
       "--aid-height", "--out", (dir / "nav").string()});
  const fs::path summary = dir / "nav/summary.json";
  // navigation grade: 25 ug -> tilt ~ 2.5e-5 rad (1.4e-3 deg); true attitude is level, yaw 0
  EXPECT_LT(std::fabs(json_number(summary, "roll_deg")), 0.01);
  EXPECT_LT(std::fabs(json_number(summary, "pitch_deg")), 0.01);
  EXPECT_EQ(json_number(summary, "duration_s"), 60.0);
}

TEST(InsCommands, BadInputIsATypedError) {
  const fs::path dir = ultratrack::test::scratch_dir();
  std::ofstream(dir / "imu.csv") << "t_s,dtheta_x_rad,dtheta_y_rad,dtheta_z_rad,dv_x_mps,dv_y_mps,dv_z_mps\n"
                                    "0.01,0,0,0,0,0,-0.098\n0.01,0,0,0,0,0,-0.098\n";
  std::ofstream(dir / "truth.csv")
      << "t_s,lat_deg,lon_deg,height_m,vel_n_mps,vel_e_mps,vel_d_mps,roll_deg,pitch_deg,yaw_deg\n"
         "0,36,127,100,0,0,0,0,0,0\n";
  try {
    run({"ins", "--imu", (dir / "imu.csv").string(), "--init", (dir / "truth.csv").string(), "--out",
         (dir / "o").string()});
    ADD_FAILURE() << "no error";
  } catch (const ultratrack::ins::InputError& e) {
    EXPECT_EQ(e.line(), 3);
  }
  EXPECT_THROW(run({"ins", "--imu", (dir / "imu.csv").string(), "--out", (dir / "o").string()}),
               ultratrack::ins::InputError);
  EXPECT_THROW(run({"imusim", "--profile", "loop", "--duration", "10", "--out", (dir / "o").string()}),
               ultratrack::ins::InputError);
  EXPECT_FALSE(fs::exists(dir / "o/nav.csv"));
}

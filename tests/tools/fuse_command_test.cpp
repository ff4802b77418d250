// SPDX-License-Identifier: GPL-3.0-or-later
// `ultratrack fuse` end to end, in process, on simulated data: a "foreign" data set (200 Hz IMU, 5 Hz GNSS
// fixes at non-integer times t = 0.137 + 0.2 k) aligned in motion converges, beats the fixes it was given and
// stays consistent with its own 1-sigma; static and configured alignments; outages; an IMU on a free-running local
// clock through its PPS record (--imu-pps); bad input is one clear InputError. Truth is the trajectory simulator's.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "command_exit.hpp"
#include "commands.hpp"
#include "ins/imu_csv.hpp"
#include "io/input_error.hpp"
#include "pipelines/fused_nav_csv.hpp"
#include "pipelines/gnss_fix_csv.hpp"
#include "run_command.hpp"
#include "support/test_data.hpp"

namespace fs = std::filesystem;
using ultratrack::io::InputError;

namespace {

void run(const std::vector<std::string>& args) { ultratrack::test_support::run_program(args); }

std::string read_text(const fs::path& f) {
  std::ifstream in(f);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// The number after "key": (first occurrence after the optional section key).
double json_number(const fs::path& file, const std::string& key, const std::string& section = "") {
  std::string text = read_text(file);
  if (!section.empty()) {
    const auto at = text.find("\"" + section + "\"");
    if (at == std::string::npos) {
      ADD_FAILURE() << section << " missing in " << file;
      return 1e300;
    }
    text = text.substr(at);
  }
  std::smatch m;
  if (!std::regex_search(text, m, std::regex("\"" + key + "\": ([-+0-9.eE]+|true|false|null)"))) {
    ADD_FAILURE() << key << " missing in " << file;
    return 1e300;
  }
  if (m[1] == "true") return 1.0;
  if (m[1] == "false" || m[1] == "null") return 0.0;
  return std::stod(m[1]);
}

// A land vehicle (10 s parked, then accelerating, turning, climbing) with an HG1700AE at 200 Hz, and 5 Hz
// fixes with white 1.5/1.5/3 m errors and 0.05 m/s velocities at t = 0.137 + 0.2 k.
fs::path make_land_data(double duration_s, const std::string& preset = "hg1700ae") {
  const fs::path dir = ultratrack::test::scratch_dir();
  run({"imusim", "--profile", "land", "--duration", std::to_string(duration_s), "--rate", "200", "--preset", preset,
       "--seed", "11", "--out", (dir / "sim").string()});
  run({"gnsssim", "--truth", (dir / "sim/truth.csv").string(), "--rate", "5", "--first", "0.137", "--seed", "5",
       "--out", (dir / "gnss.csv").string()});
  return dir;
}

void expect_converged_and_better_than_gnss(const fs::path& summary) {
  EXPECT_EQ(json_number(summary, "converged"), 1.0);
  const double fused = json_number(summary, "horizontal_m", "rms_converged");
  const double gnss = json_number(summary, "horizontal_m", "gnss_only_rms");
  // white 1.5 m per axis: GNSS-only horizontal RMS ~ 2.1 m; the INS smooths it over many fixes
  EXPECT_GT(gnss, 1.8);
  EXPECT_LT(gnss, 2.4);
  EXPECT_LT(fused, 0.7 * gnss);
  EXPECT_LT(json_number(summary, "vertical_m", "rms_converged"), json_number(summary, "vertical_m", "gnss_only_rms"));
  // HG1700AE heading once converged: well below the 1 deg convergence threshold
  EXPECT_LT(json_number(summary, "heading_deg", "rms_converged"), 0.5);
  // consistency: nearly every row within 3 sigma on all three axes (a Gaussian gives 99.2 %)
  EXPECT_GT(json_number(summary, "within_3sigma", "rms_converged"), 0.95);
  EXPECT_LE(json_number(summary, "updates_rejected"), 0.01 * json_number(summary, "fixes_used"));
}

}  // namespace

TEST(FuseCommand, ForeignRatesAndTimesAlignInMotionAndConverge) {
  const fs::path dir = make_land_data(240.0);
  run({"fuse", "--imu", (dir / "sim/imu.csv").string(), "--gnss", (dir / "gnss.csv").string(), "--coupling", "loose",
       "--filter", "ekf", "--align", "motion", "--truth", (dir / "sim/truth.csv").string(), "--quiet", "--out",
       (dir / "fuse").string()});
  const fs::path summary = dir / "fuse/summary.json";
  expect_converged_and_better_than_gnss(summary);
  // the alignment happens at a fix time (0.137 + 0.2 k) once the car moves: after the 10 s stop
  const double t0 = json_number(summary, "t_s", "alignment");
  EXPECT_GT(t0, 10.0);
  EXPECT_NEAR(std::remainder(t0 - 0.137, 0.2), 0.0, 1e-9);
  const auto rows = ultratrack::pipelines::read_fused_nav_csv(dir / "fuse/nav.csv");
  ASSERT_GT(rows.size(), 40000u);
  EXPECT_EQ(rows.front().nav.t_s, t0);  // starts exactly at the alignment time, between IMU samples
  EXPECT_NEAR(rows.back().nav.t_s, 240.0, 1e-9);
  const auto fixes = ultratrack::pipelines::read_gnss_csv(dir / "gnss.csv");
  long long after = 0;
  for (const auto& f : fixes) after += f.t_s > t0 ? 1 : 0;
  EXPECT_EQ(json_number(summary, "fixes_used"), after);
}

TEST(FuseCommand, UkfOnTheSameForeignDataConvergesToo) {
  const fs::path dir = make_land_data(240.0);
  run({"fuse", "--imu", (dir / "sim/imu.csv").string(), "--gnss", (dir / "gnss.csv").string(), "--filter", "ukf",
       "--truth", (dir / "sim/truth.csv").string(), "--quiet", "--out", (dir / "fuse").string()});
  expect_converged_and_better_than_gnss(dir / "fuse/summary.json");
}

// The car's first 10 s are parked: the HG1700AE gyrocompasses (heading ~ 1 deg/h / (15 deg/h cos L) ~ 5 deg
// at most), then the filter refines heading once the car accelerates and turns.
TEST(FuseCommand, StaticAlignmentFromTheParkedStart) {
  const fs::path dir = make_land_data(240.0);
  std::ofstream(dir / "c.toml") << "[alignment]\nstatic_duration_s = 9.0\n";
  run({"fuse", "--imu", (dir / "sim/imu.csv").string(), "--gnss", (dir / "gnss.csv").string(), "--align", "static",
       "--config", (dir / "c.toml").string(), "--truth", (dir / "sim/truth.csv").string(), "--quiet", "--out",
       (dir / "fuse").string()});
  const fs::path summary = dir / "fuse/summary.json";
  EXPECT_NEAR(json_number(summary, "t_s", "alignment"), 9.0, 0.005);
  expect_converged_and_better_than_gnss(summary);
}

TEST(FuseCommand, ConfiguredAttitudeAndAnOutage) {
  const fs::path dir = make_land_data(240.0);
  // parked level heading north at the start (the land profile's initial state)
  std::ofstream(dir / "c.toml") << "[initial]\nattitude_deg = [0.0, 0.0, 0.0]\nsigma_attitude_deg = [0.5, 0.5, 2.0]\n";
  run({"fuse", "--imu", (dir / "sim/imu.csv").string(), "--gnss", (dir / "gnss.csv").string(), "--align", "config",
       "--config", (dir / "c.toml").string(), "--outage", "150", "30", "--truth", (dir / "sim/truth.csv").string(),
       "--quiet", "--out", (dir / "fuse").string()});
  const fs::path summary = dir / "fuse/summary.json";
  EXPECT_EQ(json_number(summary, "fixes_in_outage"), 150);  // 30 s of 5 Hz fixes dropped
  const double err = json_number(summary, "horizontal_error_m", "outages");
  const double sigma = json_number(summary, "sigma_horizontal_m", "outages");
  EXPECT_GT(sigma, 0.1);
  EXPECT_LT(err, 4.0 * sigma);  // the drift is what the filter says it could be
  EXPECT_LT(err, 10.0);         // HG1700AE over 30 s after convergence
}

TEST(FuseCommand, BadInputIsOneInputError) {
  const fs::path dir = make_land_data(30.0);
  const std::string imu = (dir / "sim/imu.csv").string(), gnss = (dir / "gnss.csv").string();
  const std::string out = (dir / "fuse").string();
  EXPECT_THROW(run({"fuse", "--imu", imu, "--gnss", gnss, "--filter", "kf", "--out", out}), InputError);
  EXPECT_THROW(run({"fuse", "--imu", imu, "--gnss", gnss, "--coupling", "tight", "--out", out}), InputError);
  EXPECT_THROW(run({"fuse", "--imu", imu, "--gnss", gnss, "--align", "config", "--out", out}), InputError);
  // Never 500 m/s: not bad input but no solution (exit 3), with the speed the data show and what to change.
  std::ofstream(dir / "short.toml") << "[alignment]\nmotion_min_speed_mps = 500.0\n";
  try {
    run({"fuse", "--imu", imu, "--gnss", gnss, "--config", (dir / "short.toml").string(), "--out", out});
    ADD_FAILURE() << "aligned at 500 m/s";
  } catch (const ultratrack::tools::CommandExit& e) {
    EXPECT_EQ(e.code, 3);
    EXPECT_NE(std::string(e.what()).find("fastest"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("motion_min_speed_mps"), std::string::npos) << e.what();
  }
  std::ofstream(dir / "bad.toml") << "[filter]\nukf_alpha = -1.0\n";
  EXPECT_THROW(run({"fuse", "--imu", imu, "--gnss", gnss, "--config", (dir / "bad.toml").string(), "--out", out}),
               InputError);
  std::ofstream(dir / "g.csv")
      << "t_s,lat_deg,lon_deg,height_m,vel_n_mps,vel_e_mps,vel_d_mps,sigma_n_m,sigma_e_m,sigma_d_m\n"
         "1.0,36.37,127.36,100,,,,1,1,2\n2.0,36.37,127.36,nan,,,,1,1,2\n";
  try {
    run({"fuse", "--imu", imu, "--gnss", (dir / "g.csv").string(), "--out", out});
    ADD_FAILURE() << "NaN accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.line(), 3);
  }
  // fixes entirely after the IMU data
  std::ofstream(dir / "late.csv")
      << "t_s,lat_deg,lon_deg,height_m,vel_n_mps,vel_e_mps,vel_d_mps,sigma_n_m,sigma_e_m,sigma_d_m\n"
         "1000.0,36.37,127.36,100,,,,1,1,2\n";
  EXPECT_THROW(run({"fuse", "--imu", imu, "--gnss", (dir / "late.csv").string(), "--out", out}), InputError);
  EXPECT_FALSE(fs::exists(dir / "fuse/nav.csv"));  // nothing half-written
}

// Position-only fixes (empty velocity columns): the in-motion alignment takes the track from position
// differences and the filter updates with positions alone (the [OhAttINS] fallback).
TEST(FuseCommand, PositionOnlyFixesAlignFromPositionDifferences) {
  const fs::path dir = ultratrack::test::scratch_dir();
  run({"imusim", "--profile", "land", "--duration", "240", "--rate", "200", "--preset", "hg1700ae", "--seed", "11",
       "--out", (dir / "sim").string()});
  run({"gnsssim", "--truth", (dir / "sim/truth.csv").string(), "--rate", "5", "--first", "0.137", "--no-velocity",
       "--seed", "5", "--out", (dir / "gnss.csv").string()});
  EXPECT_FALSE(ultratrack::pipelines::read_gnss_csv(dir / "gnss.csv").front().has_velocity);
  run({"fuse", "--imu", (dir / "sim/imu.csv").string(), "--gnss", (dir / "gnss.csv").string(), "--truth",
       (dir / "sim/truth.csv").string(), "--quiet", "--out", (dir / "fuse").string()});
  const fs::path summary = dir / "fuse/summary.json";
  EXPECT_EQ(json_number(summary, "converged"), 1.0);
  EXPECT_LT(json_number(summary, "horizontal_m", "rms_converged"),
            0.7 * json_number(summary, "horizontal_m", "gnss_only_rms"));
  EXPECT_LT(json_number(summary, "heading_deg", "rms_converged"), 1.0);
}

// --odometer ([KimVMS]): with GNSS until a time, the summary's "odometer" object; without GNSS the configured
// start; a bad odometer file or no measurement at all is one InputError.
TEST(FuseCommand, OdometerWithAndWithoutGnss) {
  const fs::path dir = ultratrack::test::scratch_dir();
  run({"imusim", "--profile", "land", "--duration", "60", "--rate", "100", "--preset", "hg1700ae", "--seed", "3",
       "--odometer", "--odometer-sf", "0.01", "--out", (dir / "sim").string()});
  run({"gnsssim", "--truth", (dir / "sim/truth.csv").string(), "--rate", "1", "--seed", "5", "--out",
       (dir / "gnss.csv").string()});
  const std::string imu = (dir / "sim/imu.csv").string(), gnss = (dir / "gnss.csv").string();
  const std::string odo = (dir / "sim/odometer.csv").string(), truth = (dir / "sim/truth.csv").string();
  run({"fuse", "--imu", imu, "--gnss", gnss, "--odometer", odo, "--gnss-until", "30", "--truth", truth, "--out",
       (dir / "with").string(), "--quiet"});
  const fs::path summary = dir / "with/summary.json";
  EXPECT_GT(json_number(summary, "windows", "odometer"), 40.0);
  EXPECT_GT(json_number(summary, "updates_accepted", "odometer"), 10.0);
  EXPECT_LE(json_number(summary, "gnss_last_used_s", "odometer"), 30.0);
  EXPECT_GT(json_number(summary, "distance_travelled_m", "odometer"), 100.0);
  EXPECT_GT(json_number(summary, "fixes_after_gnss_until"), 25.0);

  EXPECT_THROW(run({"fuse", "--imu", imu, "--out", (dir / "none").string()}), InputError);
  EXPECT_THROW(run({"fuse", "--imu", imu, "--odometer", odo, "--out", (dir / "none").string()}), InputError);
  std::ofstream(dir / "odo_bad.csv") << "t_s,pulses,distance_m\n0.1,5,0.1\n0.2,5,0.1\n0.15,5,0.1\n";
  try {
    run({"fuse", "--imu", imu, "--gnss", gnss, "--odometer", (dir / "odo_bad.csv").string(), "--out",
         (dir / "bad").string()});
    ADD_FAILURE() << "time going back accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.line(), 4);
    EXPECT_NE(std::string(e.what()).find("odo_bad.csv"), std::string::npos) << e.what();
  }
}

// --imu-pps ([OhAttINS]'s time sync): the same IMU re-stamped by a free-running local clock 50 ppm fast (offset 1000.25
// s), with its PPS record (1 us jitter, one pulse missing), gives the GPS-stamped run's solution. A mapping error dt
// shifts the IMU against the fixes by dt, moving the solution by about speed x dt: the PPS fit is good to well under
// 10 us (PpsTimeSync tests), the land profile below 30 m/s, so rows agree within 30 m/s x 10 us = 0.3 mm (1 mm
// allowed for the files' rounding) and their times within 10 us.
TEST(FuseCommand, ImuOnALocalClockThroughPpsGivesTheGpsStampedSolution) {
  const fs::path dir = make_land_data(120.0);
  const std::string gnss = (dir / "gnss.csv").string(), truth = (dir / "sim/truth.csv").string();
  run({"fuse", "--imu", (dir / "sim/imu.csv").string(), "--gnss", gnss, "--truth", truth, "--quiet", "--out",
       (dir / "gps").string()});
  auto local_of = [](double t) { return 1000.25 + t * (1.0 + 50e-6); };  // t: GPS seconds since 2190 518400
  auto imu = ultratrack::ins::read_imu_csv(dir / "sim/imu.csv");
  for (auto& r : imu) r.t_s = local_of(r.t_s);
  ultratrack::ins::write_imu_csv(dir / "imu_local.csv", imu);
  std::mt19937_64 rng(7);
  std::normal_distribution<double> jitter(0.0, 1e-6);
  std::string pps = "local_s,gps_week,gps_tow_s\n";
  for (int k = 0; k <= 121; ++k)
    if (k != 60) pps += fmt::format("{:.7f},2190,{}\n", local_of(k) + jitter(rng), 518400 + k);
  std::ofstream(dir / "pps.csv") << pps;
  const std::vector<std::string> pps_args = {"fuse",
                                             "--imu",
                                             (dir / "imu_local.csv").string(),
                                             "--imu-pps",
                                             (dir / "pps.csv").string(),
                                             "--attitude-origin",
                                             "2190",
                                             "518400",
                                             "--gnss",
                                             gnss,
                                             "--truth",
                                             truth,
                                             "--quiet"};
  std::vector<std::string> args = pps_args;
  args.insert(args.end(), {"--out", (dir / "pps").string()});
  run(args);
  const auto a = ultratrack::pipelines::read_fused_nav_csv(dir / "gps/nav.csv");
  const auto b = ultratrack::pipelines::read_fused_nav_csv(dir / "pps/nav.csv");
  ASSERT_EQ(a.size(), b.size());
  ASSERT_GT(a.size(), 20000u);
  constexpr double kEarthRadius_m = 6.378e6;
  double worst_m = 0.0, worst_t_s = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const auto &x = a[i].nav, &y = b[i].nav;
    worst_t_s = std::max(worst_t_s, std::abs(x.t_s - y.t_s));
    worst_m = std::max({worst_m, kEarthRadius_m * std::abs(x.lat_rad - y.lat_rad),
                        kEarthRadius_m * std::cos(x.lat_rad) * std::abs(x.lon_rad - y.lon_rad),
                        std::abs(x.height_m - y.height_m)});
  }
  std::printf("fuse --imu-pps against GPS stamps: %zu rows, worst time difference %.3g s, position %.3g m\n", a.size(),
              worst_t_s, worst_m);
  EXPECT_LT(worst_t_s, 10e-6);
  EXPECT_LT(worst_m, 1e-3);
  EXPECT_NEAR(json_number(dir / "pps/summary.json", "horizontal_m", "rms_converged"),
              json_number(dir / "gps/summary.json", "horizontal_m", "rms_converged"), 1e-3);
  // A PPS record that stops half way does not cover the IMU file: one InputError naming the IMU file.
  std::string half = "local_s,gps_week,gps_tow_s\n";
  for (int k = 0; k <= 50; ++k) half += fmt::format("{:.7f},2190,{}\n", local_of(k), 518400 + k);
  std::ofstream(dir / "pps_half.csv") << half;
  args = pps_args;
  args[4] = (dir / "pps_half.csv").string();
  args.insert(args.end(), {"--out", (dir / "half").string()});
  try {
    run(args);
    ADD_FAILURE() << "a PPS record covering half the IMU file was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("imu_local.csv"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("beyond the PPS record"), std::string::npos) << e.what();
  }
}

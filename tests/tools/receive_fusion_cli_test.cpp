// SPDX-License-Identifier: GPL-3.0-or-later
// `ultratrack receive --imu --coupling tight` with bad IMU input: one InputError naming the IMU file and no outputs
// under their final names (a missing file, a NaN field, an IMU time line that does not cover the signal). The
// coupling's physics: tests/pipelines/receive_fusion_test.cpp (the same scenario).
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "config/scenario_toml.hpp"
#include "io/input_error.hpp"
#include "run_command.hpp"
#include "signals/rinex_nav.hpp"
#include "sim/navigation_source.hpp"
#include "sim/simulation_files.hpp"
#include "support/fusion_circle_scenario.hpp"
#include "support/test_data.hpp"

namespace fs = std::filesystem;
using namespace ultratrack;

namespace {

struct Sim {
  fs::path dir, sim, nav;
};

Sim& simulated() {
  static Sim s = [] {
    Sim r;
    r.dir = test::scratch_dir();
    r.sim = r.dir / "sim";
    test::write_fusion_circle_scenario(r.dir);
    const ultratrack::sim::Scenario scenario = config::read_scenario(r.dir / "circle.toml");
    ultratrack::sim::simulate_to_folder(scenario, r.sim, "");
    r.nav = r.dir / "nominal.rnx";
    signals::write_rinex_nav_304(r.nav, ultratrack::sim::to_rinex_nav(ultratrack::sim::load_navigation(scenario)));
    return r;
  }();
  return s;
}

std::vector<std::string> receive_args(const fs::path& rx) {
  const auto& s = simulated();
  return {
      "--input", (s.sim / "antenna0.i8.bin").string(), "--format", "i8",       "--fs", "2.0e6", "--nav", s.nav.string(),
      "--imu",   (s.sim / "imu.csv").string(),         "--out",    rx.string()};
}

}  // namespace

// Bad IMU input: one InputError naming the IMU file, and no outputs under their final names.
TEST(ReceiveFusionCli, BadImuInputIsOneInputErrorNamingTheFileAndLeavesNoOutputs) {
  const auto& s = simulated();
  auto expect_error = [&](const std::string& name, const fs::path& imu, std::vector<std::string> extra,
                          const std::string& words) {
    const auto rx = s.dir / ("bad_" + name);
    auto args = receive_args(rx);
    args[std::find(args.begin(), args.end(), "--imu") - args.begin() + 1] = imu.string();
    args.insert(args.end(), {"--coupling", "tight"});
    args.insert(args.end(), extra.begin(), extra.end());
    try {
      test_support::run_command("receive", args);
      ADD_FAILURE() << name << ": no error";
    } catch (const io::InputError& e) {
      EXPECT_EQ(e.file(), imu.string()) << name << ": " << e.what();
      EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << name << ": " << e.what();
    }
    for (const char* f : {"summary.json", "nav.csv", "solution.csv", "observations.rnx"})
      EXPECT_FALSE(fs::exists(rx / f)) << name << ": " << f;
  };
  expect_error("missing", s.dir / "no_such_imu.csv", {}, "not found");
  {
    std::ifstream in(s.sim / "imu.csv");
    std::ofstream out(s.dir / "nan_imu.csv");
    std::string line;
    for (int i = 0; std::getline(in, line); ++i) {
      if (i == 5) line = line.substr(0, line.find(',')) + ",nan" + line.substr(line.find(',', line.find(',') + 1));
      out << line << "\n";
    }
  }
  expect_error("nan", s.dir / "nan_imu.csv", {}, "");
  // The IMU's times taken as seconds since tow 518000: the signal lies ~776 s after the IMU's 16 s.
  expect_error("not_covering", s.sim / "imu.csv", {"--imu-time-origin", "518000"}, "does not cover the signal");
  EXPECT_THROW(
      test_support::run_command("receive", {"--input", (s.sim / "antenna0.i8.bin").string(), "--format", "i8", "--fs",
                                            "2.0e6", "--coupling", "loose", "--out", (s.dir / "bad_no_imu").string()}),
      io::InputError);
}

// --odometer: a bad odometer file is one InputError naming it, and no outputs; without --imu, an InputError too.
TEST(ReceiveFusionCli, ABadOdometerFileIsOneInputErrorNamingIt) {
  const auto& s = simulated();
  const fs::path good = s.dir / "odometer.csv", bad = s.dir / "odometer_backwards.csv";
  std::ofstream(good) << "t_s,pulses,distance_m\n0.1,10,0.8\n0.2,10,0.8\n0.3,10,0.8\n";
  std::ofstream(bad) << "t_s,pulses,distance_m\n0.1,10,0.8\n0.2,10,0.8\n0.15,10,0.8\n";
  auto run = [&](const std::string& name, const std::string& coupling, const fs::path& odometer) -> io::InputError {
    const auto rx = s.dir / ("odo_" + name);
    auto args = receive_args(rx);
    args.insert(args.end(), {"--coupling", coupling, "--odometer", odometer.string()});
    try {
      test_support::run_command("receive", args);
    } catch (const io::InputError& e) {
      for (const char* f : {"summary.json", "nav.csv", "solution.csv"}) EXPECT_FALSE(fs::exists(rx / f)) << name << f;
      return e;
    }
    ADD_FAILURE() << name << ": no error";
    return io::InputError("", "");
  };
  const io::InputError e = run("backwards", "loose", bad);
  EXPECT_EQ(e.file(), bad.string()) << e.what();
  EXPECT_THROW(test_support::run_command(
                   "receive", {"--input", (s.sim / "antenna0.i8.bin").string(), "--format", "i8", "--fs", "2.0e6",
                               "--odometer", good.string(), "--out", (s.dir / "odo_scalar").string()}),
               io::InputError);
}

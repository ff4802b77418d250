// SPDX-License-Identifier: GPL-3.0-or-later
// `ultratrack receive --coupling ultra-tight` on the command line: the flags that choose the loop say what the
// library's options say (the serial loop is the default: --ut-serial and --ut-pipelined=false give its bytes), and
// bad option combinations are one InputError naming the flag, before anything is written. The loop's physics is
// tested through the library: tests/pipelines/receive_ultratight_test.cpp (the same tunnel scenario).
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "config/scenario_toml.hpp"
#include "io/input_error.hpp"
#include "run_command.hpp"
#include "sim/simulation_files.hpp"
#include "support/test_data.hpp"
#include "support/ultratight_tunnel_scenario.hpp"

namespace fs = std::filesystem;
using namespace ultratrack;

namespace {

struct Sim {
  fs::path dir, sim, nav;
};

Sim& tunnel() {
  static Sim s = [] {
    Sim r;
    r.nav = test::shipped_nav_file();
    r.dir = test::scratch_dir();
    r.sim = r.dir / "sim";
    test::write_tunnel_scenario(r.dir, r.nav);
    ultratrack::sim::simulate_to_folder(config::read_scenario(r.dir / "circle.toml"), r.sim, "");
    return r;
  }();
  return s;
}

// ultratight.csv of one command-line receive with the extra flags.
std::string ultratight_log(const std::string& name, const std::vector<std::string>& extra) {
  const auto& s = tunnel();
  const auto rx = s.dir / name;
  std::vector<std::string> args = {"--input",    (s.sim / "antenna0.i8.bin").string(),
                                   "--format",   "i8",
                                   "--fs",       "2.0e6",
                                   "--nav",      s.nav.string(),
                                   "--imu",      (s.sim / "imu.csv").string(),
                                   "--align",    "motion",
                                   "--coupling", "ultra-tight",
                                   "--threads",  "2",
                                   "--out",      rx.string()};
  args.insert(args.end(), extra.begin(), extra.end());
  test_support::run_command("receive", args);
  return test::read_text_file(rx / "ultratight.csv");
}

}  // namespace

TEST(ReceiveUltraTightCli, LoopFlagsSelectTheLoops) {
  const std::string serial = ultratight_log("rx_default", {});
  const std::string pipelined = ultratight_log("rx_pipelined", {"--ut-pipelined"});
  EXPECT_GT(serial.size(), 10000u);
  EXPECT_NE(pipelined, serial);
  EXPECT_EQ(ultratight_log("rx_serial", {"--ut-serial"}), serial) << "--ut-serial is not the default";
  EXPECT_EQ(ultratight_log("rx_pipelined_false", {"--ut-pipelined=false"}), serial)
      << "--ut-pipelined=false is not the serial default";
}

TEST(ReceiveUltraTightCli, BadOptionsAreOneInputError) {
  const auto& s = tunnel();
  const std::vector<std::string> base = {
      "--input", (s.sim / "antenna0.i8.bin").string(), "--format", "i8", "--fs", "2.0e6", "--nav", s.nav.string()};
  auto expect_error = [&](const std::string& name, std::vector<std::string> extra, const std::string& words) {
    auto args = base;
    args.insert(args.end(), extra.begin(), extra.end());
    args.insert(args.end(), {"--out", (s.dir / ("bad_" + name)).string()});
    try {
      test_support::run_command("receive", args);
      ADD_FAILURE() << name << ": no error";
    } catch (const io::InputError& e) {
      EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << name << ": " << e.what();
    }
    EXPECT_FALSE(fs::exists(s.dir / ("bad_" + name) / "summary.json")) << name;
  };
  expect_error("no_imu", {"--coupling", "ultra-tight"}, "--coupling ultra-tight needs --imu");
  expect_error("form_without_ut",
               {"--imu", (s.sim / "imu.csv").string(), "--coupling", "tight", "--ut-measurement", "iq"},
               "--ut-measurement needs --coupling ultra-tight");
  expect_error("form_scalar", {"--ut-measurement", "iq"}, "--ut-measurement needs --coupling ultra-tight");
  expect_error("pipelined_scalar", {"--ut-pipelined"}, "--ut-pipelined needs --coupling ultra-tight");
  expect_error("serial_scalar", {"--ut-serial"}, "--ut-serial needs --coupling ultra-tight");
  expect_error("serial_tight", {"--imu", (s.sim / "imu.csv").string(), "--coupling", "tight", "--ut-serial"},
               "--ut-serial needs --coupling ultra-tight");
  expect_error("serial_and_pipelined",
               {"--imu", (s.sim / "imu.csv").string(), "--coupling", "ultra-tight", "--ut-serial", "--ut-pipelined"},
               "--ut-serial and --ut-pipelined exclude each other");
  expect_error("pipelined_tight", {"--imu", (s.sim / "imu.csv").string(), "--coupling", "tight", "--ut-pipelined"},
               "--ut-pipelined needs --coupling ultra-tight");
  expect_error("bad_form",
               {"--imu", (s.sim / "imu.csv").string(), "--coupling", "ultra-tight", "--ut-measurement", "phase"},
               "--ut-measurement must be iq or discriminator");
  expect_error("clock_loop_scalar", {"--ut-clock-loop-bw", "5"}, "--ut-clock-loop-bw needs --coupling ultra-tight");
  expect_error("clock_loop_tight",
               {"--imu", (s.sim / "imu.csv").string(), "--coupling", "tight", "--ut-clock-loop-bw", "5"},
               "--ut-clock-loop-bw needs --coupling ultra-tight");
  for (const char* bw : {"-1", "13", "nan"})
    expect_error(std::string("clock_loop_bw_") + bw,
                 {"--imu", (s.sim / "imu.csv").string(), "--coupling", "ultra-tight", "--ut-clock-loop-bw", bw},
                 "--ut-clock-loop-bw must be 0 (off) or in (0, 12.5] Hz");
  expect_error("bad_coupling", {"--coupling", "ultratight"}, "ultra-tight");
  expect_error("missing_imu_file", {"--imu", (s.dir / "none.csv").string(), "--coupling", "ultra-tight"}, "not found");
  expect_error("nis_scalar", {"--nis-window", "20"}, "--nis-window and --nis-probability need --coupling vector");
  expect_error("nis_window_zero",
               {"--imu", (s.sim / "imu.csv").string(), "--coupling", "ultra-tight", "--nis-window", "0"},
               "the window must hold at least 1 update");
  expect_error("nis_probability_one", {"--coupling", "vector", "--nis-probability", "1"},
               "the probability must lie in (0, 1)");
}

// SPDX-License-Identifier: GPL-3.0-or-later
// `ultratrack simulate` through CLI11 as main() runs it: a missing or broken scenario is an InputError
// (exit 2 in main) naming the scenario file; a good one writes the outputs into --out.
#include <gtest/gtest.h>

#include <CLI/Error.hpp>  // CLI::ParseError only: the whole of CLI11 is run_command.cpp's
#include <algorithm>
#include <fstream>
#include <string>
#include <vector>

#include "commands.hpp"
#include "run_command.hpp"
#include "signals/input_error.hpp"
#include "support/test_data.hpp"

namespace {

void run(std::vector<std::string> args) {
  ultratrack::test_support::run_command("simulate", std::move(args), /*quiet=*/false);
}

std::string input_error(std::vector<std::string> args) {
  try {
    run(std::move(args));
  } catch (const ultratrack::signals::InputError& e) {
    return e.what();
  }
  return "no InputError";
}

}  // namespace

TEST(SimulateCommand, BadScenarioIsInputErrorNamingTheFile) {
  const auto dir = ultratrack::test::scratch_dir();
  const std::string bad = (dir / "bad.toml").string();
  { std::ofstream(bad) << "[signal]\nsample_rate_hz = \"fast\"\n"; }
  auto e = input_error({"--scenario", bad, "--out", (dir / "out").string(), "--quiet"});
  EXPECT_NE(e.find("bad.toml:2"), std::string::npos) << e;
  EXPECT_NE(e.find("signal.sample_rate_hz"), std::string::npos) << e;
  e = input_error({"--scenario", (dir / "absent.toml").string(), "--out", (dir / "out").string()});
  EXPECT_NE(e.find("absent.toml"), std::string::npos) << e;
  const std::string no_rinex = (dir / "no_rinex.toml").string();
  { std::ofstream(no_rinex) << "[navigation]\nrinex = \"missing.22n\"\n"; }
  e = input_error({"--scenario", no_rinex, "--out", (dir / "out").string()});
  EXPECT_NE(e.find("missing.22n"), std::string::npos) << e;
  EXPECT_THROW(run({"--scenario", bad}), CLI::ParseError);  // --out is required
}

TEST(SimulateCommand, WritesTheOutputs) {
  const auto dir = ultratrack::test::scratch_dir();
  const std::string s = (dir / "s.toml").string();
  { std::ofstream(s) << "[signal]\nsample_rate_hz = 2e6\nduration_s = 0.05\nformat = \"f32\"\n"; }
  run({"--scenario", s, "--out", (dir / "out").string(), "--quiet"});
  for (const char* f : {"antenna0.f32.bin", "truth.csv", "satellites.csv", "scenario.toml", "summary.json"})
    EXPECT_TRUE(std::filesystem::exists(dir / "out" / f)) << f;
  EXPECT_EQ(std::filesystem::file_size(dir / "out" / "antenna0.f32.bin"), 100000u * 8);
}

// SPDX-License-Identifier: GPL-3.0-or-later
// `ultratrack receive` on a synthetic file read with wrong flags (issue 3's bad input, without ../shared/data):
// a wrong format, a wrong rate and a 2-bit file read as 8-bit find no satellite (InputError naming the file,
// no outputs), a wrong 2-bit order fails with a message naming the file; the right flags on a file too short for a fix
// give exit 3 with a message naming the file and every output written up to the end. (Empty, truncated and
// unknown-format files: cmd_receive_test.cpp.)
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "command_exit.hpp"
#include "commands.hpp"
#include "run_command.hpp"
#include "signals/input_error.hpp"
#include "support/test_data.hpp"

namespace fs = std::filesystem;

namespace {

void run(const std::string& command, std::vector<std::string> args) {
  ultratrack::test_support::run_command(command, std::move(args));
}

fs::path simulate(const fs::path& dir, const std::string& format) {
  std::ofstream(dir / (format + ".toml")) << "[signal]\nsample_rate_hz = 4e6\nformat = \"" << format
                                          << "\"\nduration_s = 0.5\ncn0_dbhz = 45.0\n[time]\ngps_week = 2190\n"
                                             "tow_s = 518400.0\n[navigation]\nconstellation = \"nominal\"\n"
                                             "[receiver]\nllh_deg_m = [35.274016, 137.013759, 100.0]\n";
  run("simulate", {"--scenario", (dir / (format + ".toml")).string(), "--out", (dir / format).string()});
  return dir / format / ("antenna0." + format + ".bin");
}

void expect_no_satellite(const fs::path& file, std::vector<std::string> flags, const fs::path& out) {
  flags.insert(flags.end(), {"--input", file.string(), "--out", out.string()});
  try {
    run("receive", flags);
    FAIL() << "no error";
  } catch (const ultratrack::signals::InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(file.string()), std::string::npos) << what;
    EXPECT_NE(what.find("no GPS L1 C/A satellite"), std::string::npos) << what;
  }
  EXPECT_FALSE(fs::exists(out) && !fs::is_empty(out)) << "outputs written for " << file;
}

}  // namespace

TEST(ReceiveBadInput, WrongFormatOrRateFindsNoSatelliteAndNamesTheFile) {
  const auto dir = ultratrack::test::scratch_dir();
  const auto i8 = simulate(dir, "i8");
  const auto i2 = simulate(dir, "i2");
  expect_no_satellite(i8, {"--format", "i16", "--fs", "4e6"}, dir / "out1");   // wrong format
  expect_no_satellite(i8, {"--format", "i8", "--fs", "2.6e6"}, dir / "out2");  // wrong rate
  expect_no_satellite(i2, {"--format", "i8", "--fs", "4e6"}, dir / "out3");    // 2-bit read as 8-bit
  // The wrong bit order turns each byte's (I0, Q0, I1, Q1) into (Q1, I1, Q0, I0): acquisition may still find
  // mirrored peaks, tracking cannot hold them; either way a non-zero exit whose message names the file.
  try {
    run("receive", {"--input", i2.string(), "--format", "i2", "--fs", "4e6", "--2bit-order", "msb-first", "--out",
                    (dir / "out4").string()});
    FAIL() << "no error for the wrong bit order";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find(i2.string()), std::string::npos) << e.what();
  }
}

TEST(ReceiveBadInput, FileEndingBeforeAFixExitsThreeWithEveryOutput) {
  const auto dir = ultratrack::test::scratch_dir();
  const auto i2 = simulate(dir, "i2");
  const auto out = dir / "out";
  try {
    run("receive", {"--input", i2.string(), "--format", "i2", "--fs", "4e6", "--out", out.string()});
    FAIL() << "a fix from 0.5 s?";
  } catch (const ultratrack::tools::CommandExit& e) {
    EXPECT_EQ(e.code, 3);
    const std::string what = e.what();
    EXPECT_NE(what.find(i2.string()), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
  for (const char* name : {"solution.csv", "observations.rnx", "navigation.rnx", "solution.nmea", "solution.kml",
                           "tracking.csv", "summary.json"})
    EXPECT_TRUE(fs::exists(out / name)) << name;
  std::ifstream in(out / "summary.json");
  std::stringstream s;
  s << in.rdbuf();
  EXPECT_NE(s.str().find("\"fix\": false"), std::string::npos);
  EXPECT_NE(s.str().find("\"format\": \"i2 (twos, lsb-first)\""), std::string::npos) << s.str();
}

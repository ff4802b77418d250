// SPDX-License-Identifier: GPL-3.0-or-later
// Faults around `ultratrack receive` (issue 21's fault injection): an input that is a directory, an output folder
// that cannot be made (its parent is a file), and a disk that fills mid-run (a file-size limit, RLIMIT_FSIZE, with
// SIGXFSZ ignored so that the write fails as on a full disk). Each gives one error naming the path and the
// problem; the file being written is removed, never left half-written under its final name or as a .partial.
#include <gtest/gtest.h>
#include <sys/resource.h>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "io/input_error.hpp"
#include "run_command.hpp"
#include "support/test_data.hpp"

namespace fs = std::filesystem;

namespace {

void run(const std::string& command, std::vector<std::string> args) {
  ultratrack::test_support::run_command(command, std::move(args));
}

// 2 s at 2.6 MHz of the nominal constellation (10 MB): tracking.csv of a receive is ~55 kB.
fs::path simulate(const fs::path& dir) {
  std::ofstream(dir / "s.toml") << "[signal]\nsample_rate_hz = 2.6e6\nduration_s = 2.0\n[time]\ngps_week = 2190\n"
                                   "tow_s = 518400.0\n[navigation]\nconstellation = \"nominal\"\n";
  run("simulate", {"--scenario", (dir / "s.toml").string(), "--out", (dir / "sim").string()});
  return dir / "sim" / "antenna0.i8.bin";
}

std::string error_of(const std::vector<std::string>& args) {
  try {
    run("receive", args);
  } catch (const ultratrack::io::InputError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(FaultInjection, InputThatIsADirectoryIsNamed) {
  const auto dir = ultratrack::test::scratch_dir();
  const std::string e =
      error_of({"--input", dir.string(), "--format", "i8", "--fs", "2.6e6", "--out", (dir / "rx").string()});
  EXPECT_NE(e.find(dir.string()), std::string::npos) << e;
  EXPECT_NE(e.find("not a regular file"), std::string::npos) << e;
  EXPECT_FALSE(fs::exists(dir / "rx"));
}

TEST(FaultInjection, OutputFolderUnderAFileIsNamed) {
  const auto dir = ultratrack::test::scratch_dir();
  const fs::path input = simulate(dir);
  const fs::path out = input / "rx";  // a folder inside a regular file
  const std::string e = error_of({"--input", input.string(), "--format", "i8", "--fs", "2.6e6", "--out", out.string()});
  EXPECT_NE(e.find(out.string()), std::string::npos) << e;
  EXPECT_NE(e.find("cannot create the output folder"), std::string::npos) << e;
}

TEST(FaultInjection, DiskFullMidRunLeavesNoHalfWrittenFile) {
  const auto dir = ultratrack::test::scratch_dir();
  const fs::path input = simulate(dir);
  const fs::path out = dir / "rx";
  rlimit before{};
  ASSERT_EQ(getrlimit(RLIMIT_FSIZE, &before), 0);
  const auto previous_xfsz = std::signal(SIGXFSZ, SIG_IGN);
  rlimit limited = before;
  limited.rlim_cur = 20 * 1024;  // tracking.csv outgrows it; the small outputs fit
  ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &limited), 0);
  const std::string e = error_of({"--input", input.string(), "--format", "i8", "--fs", "2.6e6", "--out", out.string()});
  setrlimit(RLIMIT_FSIZE, &before);
  std::signal(SIGXFSZ, previous_xfsz);
  EXPECT_NE(e.find((out / "tracking.csv").string()), std::string::npos) << e;
  EXPECT_NE(e.find("write failed"), std::string::npos) << e;
  EXPECT_FALSE(fs::exists(out / "tracking.csv"));
  for (const auto& f : fs::directory_iterator(out))
    EXPECT_NE(f.path().extension(), ".partial") << f.path();  // no temporary left behind
}

}  // namespace

// SPDX-License-Identifier: GPL-3.0-or-later
// A [[step]] campaign (tools/campaign_steps.hpp) through `ultratrack campaign run`: each run's [[file]] written with
// its parameters, its steps run as the program in the run's folder, JSON scalars in complete.csv (imusim's row count
// = duration x rate), [compute] remove applied, and a step that exits non-zero reported with its log.
#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "command_exit.hpp"
#include "io/input_error.hpp"
#include "run_command.hpp"
#include "support/test_data.hpp"

namespace {

namespace fs = std::filesystem;
using ultratrack::test::read_text_file;
using ultratrack::test_support::run_command;

TEST(CampaignSteps, RunsTheStepsInEachRunFolderAndReportsAFailingStep) {
  const fs::path dir = ultratrack::test::scratch_dir(), out = dir / "out";
  std::ofstream(dir / "note.txt") << "rate {rate} in {campaign_dir}\n";
  // The second run asks imusim for 5 Hz, outside its 50-1000 Hz: that step exits non-zero.
  std::ofstream(dir / "c.toml") << "[campaign]\nname = \"steps\"\n"
                                   "[[axis]]\nname = \"seed\"\nvalues = [3, 4, 5]\nrate = [50, 100, 5]\n"
                                   "[[file]]\ntemplate = \"note.txt\"\nname = \"note.txt\"\n"
                                   "[[step]]\nargs = [\"imusim\", \"--profile\", \"static\", \"--duration\", \"2\", "
                                   "\"--rate\", \"{rate}\", \"--seed\", \"{seed}\", \"--out\", \"s\"]\n"
                                   "[compute]\nremove = [\"s/imu.csv\"]\n"
                                   "json = { rows = \"s/summary.json:imu_rows\", gyro_y = "
                                   "\"s/summary.json:gyro_turn_on_bias_dph.1\" }\n"
                                   "[[report]]\nkind = \"table\"\ncolumns = [\"seed\", \"rows\"]\n";
  int code = 0;
  try {
    run_command("campaign", {"run", (dir / "c.toml").string(), "--out", out.string(), "--jobs", "2", "--program",
                             ULTRATRACK_PROGRAM});
  } catch (const ultratrack::tools::CommandExit& e) {
    code = e.code;
  }
  EXPECT_EQ(code, 1);
  EXPECT_EQ(read_text_file(out / "runs/0001/note.txt"), "rate 100 in " + fs::absolute(dir).string() + "\n");
  EXPECT_TRUE(fs::exists(out / "runs/0000/s/truth.csv"));
  EXPECT_FALSE(fs::exists(out / "runs/0000/s/imu.csv")) << "removed by [compute] remove";
  const std::string complete = read_text_file(out / "runs/0001/complete.csv");
  EXPECT_NE(complete.find("rows,200\n"), std::string::npos) << complete;  // 2 s x 100 Hz
  EXPECT_NE(complete.find("gyro_y,"), std::string::npos) << complete;
  const std::string report = read_text_file(out / "report.txt");
  EXPECT_NE(report.find("3 runs: 2 complete, 1 failed, 0 missing"), std::string::npos) << report;
  EXPECT_NE(report.find("| 3 | 100 |\n| 4 | 200 |\n"), std::string::npos) << report;
  EXPECT_NE(report.find("failed: 0002 (seed=5 rate=5): step 1 (ultratrack imusim"), std::string::npos) << report;
  EXPECT_NE(report.find("steps.log"), std::string::npos) << report;
  EXPECT_NE(read_text_file(out / "runs/0002/steps.log").find("$ " ULTRATRACK_PROGRAM " imusim"), std::string::npos);
}

TEST(CampaignSteps, UnknownParameterInAStepIsAnInputErrorBeforeAnyRun) {
  const fs::path dir = ultratrack::test::scratch_dir();
  std::ofstream(dir / "c.toml") << "[[axis]]\nname = \"seed\"\nvalues = [1]\n"
                                   "[[step]]\nargs = [\"imusim\", \"--seed\", \"{sed}\"]\n";
  try {
    run_command("campaign", {"run", (dir / "c.toml").string(), "--out", (dir / "out").string()});
    FAIL() << "no InputError";
  } catch (const ultratrack::io::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("{sed} names no campaign parameter"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(dir / "out"));
}

}  // namespace

// SPDX-License-Identifier: GPL-3.0-or-later
// `ultratrack campaign run|run-one|report` as the program runs them: the local engine, resume, a failing run
// reported (exit 1), a malformed campaign file (InputError naming the file and the key), and the Slurm engine
// against fake `sbatch` and `squeue` on PATH that run the array tasks here (the script's content, the wait, the
// resume that submits only what is missing).
#include <gtest/gtest.h>

#include <cstdlib>
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

// Two 2 s static files; the second receive asks for the tight coupling without an IMU: it fails.
fs::path tiny_campaign(const fs::path& dir) {
  const std::string nav = ultratrack::test::shipped_nav_file().string();
  std::ofstream(dir / "s.toml") << "[signal]\nsample_rate_hz = 2.0e6\nformat = \"i8\"\nduration_s = 2.0\n"
                                   "cn0_dbhz = 45.0\nseed = {seed}\n[time]\ngps_week = "
                                << ultratrack::test::shipped_nav_week
                                << "\ntow_s = " << ultratrack::test::shipped_nav_tow_s << "\n[navigation]\nrinex = \""
                                << nav << "\"\nelevation_mask_deg = 30.0\n";
  std::ofstream(dir / "c.toml") << "[campaign]\nname = \"tiny\"\n[[axis]]\nname = \"seed\"\nvalues = [7, 8]\n"
                                   "coupling = [\"scalar\", \"tight\"]\n[simulate]\nscenario = \"s.toml\"\n"
                                   "[receive]\nnav = \""
                                << nav
                                << "\"\ncoupling = \"{coupling}\"\n"
                                   "[compute]\nlock_outcomes = { lock_deadline_s = 1.5 }\n"
                                   "[[report]]\nkind = \"lock_threshold\"\nlevel = \"seed\"\n"
                                   "[slurm]\ntime = \"00:05:00\"\nmem = \"1G\"\nextra = [\"--qos=test\"]\n";
  return dir / "c.toml";
}

int exit_code(const std::string& command, std::vector<std::string> args, bool quiet = true) {
  try {
    run_command(command, std::move(args), quiet);
  } catch (const ultratrack::tools::CommandExit& e) {
    return e.code;
  } catch (const ultratrack::io::InputError&) {
    return 2;
  }
  return 0;
}

fs::path run_dir(const fs::path& out, int index) { return out / "runs" / (index == 0 ? "0000" : "0001"); }

TEST(CampaignCommand, LocalRunsResumesAndReportsTheFailure) {
  const fs::path dir = ultratrack::test::scratch_dir();
  const fs::path campaign = tiny_campaign(dir), out = dir / "out";
  EXPECT_EQ(exit_code("campaign", {"run", campaign.string(), "--out", out.string(), "--jobs", "2"}), 1);
  EXPECT_TRUE(fs::exists(run_dir(out, 0) / "complete.csv"));
  EXPECT_TRUE(fs::exists(run_dir(out, 1) / "failed.txt"));
  const std::string report = read_text_file(out / "report.txt");
  EXPECT_NE(report.find("2 runs: 1 complete, 1 failed, 0 missing"), std::string::npos) << report;
  EXPECT_NE(report.find("failed: 0001 (seed=8 coupling=tight)"), std::string::npos) << report;

  // Resume: the complete run stays as it is; `campaign report` reads the folder again.
  { std::ofstream(run_dir(out, 0) / "sentinel") << "x"; }
  EXPECT_EQ(exit_code("campaign", {"run", campaign.string(), "--out", out.string()}), 1);
  EXPECT_TRUE(fs::exists(run_dir(out, 0) / "sentinel"));
  fs::remove(out / "report.txt");
  EXPECT_EQ(exit_code("campaign", {"report", out.string()}, false), 0);
  EXPECT_EQ(read_text_file(out / "report.txt"), report);

  // run-one of the failing run: exit 1 with its message.
  EXPECT_EQ(exit_code("campaign", {"run-one", out.string(), "1"}, false), 1);
  EXPECT_EQ(exit_code("campaign", {"run-one", out.string(), "2"}, false), 2);  // no run 2

  // The same folder with another campaign: refused before anything runs.
  std::ofstream(campaign, std::ios::app) << "\n# changed\n";
  EXPECT_EQ(exit_code("campaign", {"run", campaign.string(), "--out", out.string()}), 2);
}

TEST(CampaignCommand, MalformedCampaignIsInputErrorNamingFileAndKey) {
  const fs::path dir = ultratrack::test::scratch_dir();
  std::ofstream(dir / "s.toml") << "[signal]\n";
  std::ofstream(dir / "bad.toml") << "[simulate]\nscenario = \"s.toml\"\n[slurm]\ncpus = 4\n";
  try {
    run_command("campaign", {"run", (dir / "bad.toml").string(), "--out", (dir / "out").string()});
    FAIL() << "no InputError";
  } catch (const ultratrack::io::InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find((dir / "bad.toml").string()), std::string::npos) << what;
    EXPECT_NE(what.find("unknown key 'slurm.cpus'"), std::string::npos) << what;
  }
  EXPECT_FALSE(fs::exists(dir / "out")) << "nothing is written for a malformed campaign";
}

// sbatch and squeue stand-ins: sbatch keeps the script, runs each array task in the background with
// SLURM_ARRAY_TASK_ID set, and answers a job id; squeue lists the job until every task has ended.
void install_fake_slurm(const fs::path& bin, const fs::path& state) {
  fs::create_directories(bin);
  std::ofstream(bin / "sbatch")
      << "#!/bin/bash\n"
         "[ \"$1\" = --parsable ] || { echo 'expected --parsable' >&2; exit 9; }\n"
         "state="
      << state.string()
      << "\n"
         "n=$(ls \"$state\" | grep -c '^submitted' || true)\n"
         "cp \"$2\" \"$state/submitted_$n.sbatch\"\n"
         "rm -f \"$state/done\"\n"
         "read first last < <(sed -n 's/^#SBATCH --array=\\([0-9]*\\)-\\([0-9]*\\).*/\\1 \\2/p' \"$2\")\n"
         "( sleep 0.3; for ((k = first; k <= last; k++)); do\n"
         "    SLURM_ARRAY_TASK_ID=$k bash \"$2\" > \"$state/task_$k.log\" 2>&1; done\n"
         "  touch \"$state/done\" ) > /dev/null 2>&1 &\n"
         "echo \"424$n;testcluster\"\n";
  std::ofstream(bin / "squeue") << "#!/bin/bash\n"
                                   "state="
                                << state.string()
                                << "\n"
                                   "echo x >> \"$state/squeue_calls\"\n"
                                   "[ -f \"$state/done\" ] || echo \"$3_0 R\"\n";
  fs::permissions(bin / "sbatch", fs::perms::owner_all);
  fs::permissions(bin / "squeue", fs::perms::owner_all);
}

TEST(CampaignCommand, SlurmEngineSubmitsAnArrayWaitsAndResumes) {
  const fs::path dir = ultratrack::test::scratch_dir();
  const fs::path campaign = tiny_campaign(dir), out = dir / "out", state = dir / "slurm_state";
  fs::create_directories(state);
  install_fake_slurm(dir / "bin", state);
  const std::string path = std::getenv("PATH") ? std::getenv("PATH") : "";
  setenv("PATH", ((dir / "bin").string() + ":" + path).c_str(), 1);
  const std::vector<std::string> slurm{"run",       campaign.string(),  "--out",    out.string(), "--engine", "slurm",
                                       "--program", ULTRATRACK_PROGRAM, "--poll-s", "0.2"};
  EXPECT_EQ(exit_code("campaign", slurm), 1);  // one run fails
  const std::string script = read_text_file(state / "submitted_0.sbatch");
  EXPECT_NE(script.find("#SBATCH --array=0-1\n"), std::string::npos) << script;
  EXPECT_NE(script.find("#SBATCH --job-name=ultratrack-tiny\n"), std::string::npos) << script;
  EXPECT_NE(script.find("#SBATCH --time=00:05:00\n"), std::string::npos) << script;
  EXPECT_NE(script.find("#SBATCH --mem=1G\n"), std::string::npos) << script;
  EXPECT_NE(script.find("#SBATCH --cpus-per-task=1\n"), std::string::npos) << script;
  EXPECT_NE(script.find("#SBATCH --qos=test\n"), std::string::npos) << script;
  EXPECT_NE(script.find(std::string(ULTRATRACK_PROGRAM) + "' campaign run-one '" + fs::absolute(out).string()),
            std::string::npos)
      << script;
  EXPECT_TRUE(fs::exists(state / "squeue_calls")) << "the engine waits on squeue";
  EXPECT_TRUE(fs::exists(run_dir(out, 0) / "complete.csv"));
  EXPECT_TRUE(fs::exists(run_dir(out, 1) / "failed.txt"));
  EXPECT_NE(read_text_file(out / "report.txt").find("1 complete, 1 failed"), std::string::npos);

  // Resume: only the failed run is pending, so the array has one task and run 0 is left alone.
  { std::ofstream(run_dir(out, 0) / "sentinel") << "x"; }
  fs::remove(state / "squeue_calls");
  EXPECT_EQ(exit_code("campaign", slurm), 1);
  EXPECT_EQ(read_text_file(out / "slurm" / "pending.txt"), "1\n");
  EXPECT_NE(read_text_file(state / "submitted_1.sbatch").find("#SBATCH --array=0-0\n"), std::string::npos);
  EXPECT_TRUE(fs::exists(run_dir(out, 0) / "sentinel"));

  // --no-wait returns at once, without asking squeue.
  fs::remove(state / "squeue_calls");
  std::vector<std::string> no_wait = slurm;
  no_wait.push_back("--no-wait");
  EXPECT_EQ(exit_code("campaign", no_wait), 0);
  EXPECT_FALSE(fs::exists(state / "squeue_calls"));
  for (int i = 0; i < 100 && !fs::exists(state / "done"); ++i) usleep(100000);  // let the background task end
  setenv("PATH", path.c_str(), 1);
}

}  // namespace

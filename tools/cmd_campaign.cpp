// SPDX-License-Identifier: GPL-3.0-or-later
// `ultratrack campaign`: many runs from one campaign file (config/campaign_toml.hpp), and their report.
//   campaign run C.toml --out DIR [--engine local|slurm] [--jobs N] [--no-wait]   runs what is not complete yet
//   campaign run-one DIR INDEX                                                    one run (a Slurm array task)
//   campaign report DIR                                                           the report of what is complete
// Each run lands in DIR/runs/NNNN (pipelines/campaign_run.hpp); the report goes to stdout and DIR/report.txt.
// Exit: 0 when every run is complete (report: always, it says what is missing), 1 when a run failed (its
// message is in the report and DIR/runs/NNNN/failed.txt), 2 for a malformed campaign file or bad arguments.
#include <fmt/core.h>

#include <CLI/CLI.hpp>
#include <filesystem>
#include <memory>
#include <string>
#include <thread>

#include "campaign_engines.hpp"
#include "cli_parse.hpp"
#include "command_exit.hpp"
#include "commands.hpp"
#include "interrupt_guard.hpp"
#include "io/atomic_file.hpp"
#include "io/input_error.hpp"
#include "pipelines/campaign_report.hpp"

namespace ultratrack::tools {
namespace {

namespace fs = std::filesystem;

struct CampaignArgs {
  std::string campaign, out, engine = "local", jobs, program, poll_s = "10", index;
  bool no_wait = false, quiet = false;
};

std::string report(const fs::path& out) {
  const config::CampaignFile campaign = load_campaign_dir(out);
  const std::string text =
      pipelines::campaign_report(out, pipelines::expand_campaign(campaign.axes), campaign.reductions);
  io::write_file_atomically(out / "report.txt", text);
  return text;
}

int failed_runs(const fs::path& out) {
  const config::CampaignFile campaign = load_campaign_dir(out);
  int failed = 0;
  for (const pipelines::CampaignRun& run : pipelines::expand_campaign(campaign.axes))
    failed += pipelines::campaign_run_status(pipelines::campaign_run_dir(out, run.index)).state ==
              pipelines::CampaignRunState::kFailed;
  return failed;
}

// The ultratrack that Slurm tasks and [[step]] runs execute: --program, or this program.
fs::path program_of(const CampaignArgs& args) {
  return args.program.empty() ? fs::read_symlink("/proc/self/exe") : fs::absolute(args.program);
}

void run_campaign(const CampaignArgs& args) {
  const fs::path out = args.out;
  const config::CampaignFile campaign = prepare_campaign_dir(args.campaign, out);
  std::FILE* log = args.quiet ? nullptr : stderr;
  if (args.engine == "local") {
    const int threads = std::max(1, campaign.receive.threads);
    const int jobs = args.jobs.empty() ? std::max(1, static_cast<int>(std::thread::hardware_concurrency()) / threads)
                                       : parse_int_option("--jobs", args.jobs);
    if (jobs < 1) throw io::InputError("command line", "--jobs: at least 1");
    InterruptGuard interrupt;
    run_campaign_local(campaign, out, jobs, program_of(args), log, interrupt.token());
  } else if (args.engine == "slurm") {
    const fs::path program = program_of(args);
    const double poll_s = parse_double_option("--poll-s", args.poll_s);
    const SlurmSubmission s = run_campaign_slurm(campaign, out, program, args.no_wait, poll_s, log);
    if (s.job_id.empty() && log) fmt::print(log, "campaign: every run is complete; nothing submitted\n");
    if (args.no_wait && !s.job_id.empty()) {
      fmt::print("campaign: Slurm job {} submitted ({} runs); `ultratrack campaign report {}` when it is done\n",
                 s.job_id, s.runs, out.string());
      return;
    }
  } else {
    throw io::InputError("command line", "--engine must be local or slurm, got '" + args.engine + "'");
  }
  fmt::print("{}", report(out));
  if (const int failed = failed_runs(out); failed > 0)
    throw CommandExit(1, fmt::format("{} run(s) failed (see the report, {}/report.txt)", failed, out.string()));
}

void run_one(const CampaignArgs& args) {
  const fs::path out = args.out;
  const config::CampaignFile campaign = load_campaign_dir(out);
  const int index = parse_int_option("INDEX", args.index);
  InterruptGuard interrupt;
  if (!run_campaign_index(campaign, out, index, program_of(args), interrupt.token())) {
    const auto status = pipelines::campaign_run_status(pipelines::campaign_run_dir(out, index));
    throw CommandExit(1, fmt::format("run {} failed: {}", pipelines::campaign_run_folder(index),
                                     status.message.empty() ? "stopped" : status.message));
  }
}

}  // namespace

void add_campaign_command(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "campaign",
      "Campaigns: many runs (simulate and receive, command steps, Monte Carlos) from one file, locally or on Slurm");
  cmd->require_subcommand(1);
  auto args = std::make_shared<CampaignArgs>();

  auto* run = cmd->add_subcommand("run", "Run the campaign's runs that are not complete yet, then print the report");
  run->add_option("CAMPAIGN", args->campaign, "campaign file (TOML)")->required();
  run->add_option("--out", args->out, "output folder (one subfolder per run; resumes what is there)")->required();
  run->add_option("--engine", args->engine, "local (this machine's cores) or slurm (an sbatch array job)")
      ->capture_default_str();
  run->add_option("--jobs", args->jobs, "local: runs at once (default: cores / [receive] threads)");
  run->add_flag("--no-wait", args->no_wait, "slurm: return once submitted");
  run->add_option("--program", args->program,
                  "the ultratrack that Slurm tasks and [[step]] runs execute (default: this program)");
  run->add_option("--poll-s", args->poll_s, "slurm: seconds between squeue polls")->capture_default_str();
  run->add_flag("--quiet", args->quiet, "no line per finished run");
  run->callback([args] { run_campaign(*args); });

  auto* one = cmd->add_subcommand("run-one", "Run one run of a campaign folder (what a Slurm array task calls)");
  one->add_option("DIR", args->out, "campaign output folder")->required();
  one->add_option("INDEX", args->index, "run index (0-based)")->required();
  one->add_option("--program", args->program, "the ultratrack that [[step]] runs execute (default: this program)");
  one->callback([args] { run_one(*args); });

  auto* rep =
      cmd->add_subcommand("report", "Report a campaign folder: what is complete, failed, missing, and the tables");
  rep->add_option("DIR", args->out, "campaign output folder")->required();
  rep->callback([args] { fmt::print("{}", report(args->out)); });
}

}  // namespace ultratrack::tools

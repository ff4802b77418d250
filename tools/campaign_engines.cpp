// SPDX-License-Identifier: GPL-3.0-or-later
#include "campaign_engines.hpp"

#include <fmt/core.h>
#include <sys/wait.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "campaign_steps.hpp"
#include "io/atomic_file.hpp"
#include "io/input_error.hpp"
#include "pipelines/campaign_run.hpp"

namespace ultratrack::tools {
namespace {

namespace fs = std::filesystem;

std::string read_text(const fs::path& file) {
  std::ifstream in(file);
  if (!in) throw io::InputError(file.string(), "cannot read the file");
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// A command's standard output (popen), and its exit status (-1 when it did not exit normally).
std::pair<std::string, int> capture(const std::string& command) {
  std::FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) throw std::runtime_error("cannot run: " + command);
  std::string out;
  char buffer[4096];
  while (const std::size_t n = std::fread(buffer, 1, sizeof buffer, pipe)) out.append(buffer, n);
  const int status = pclose(pipe);
  return {out, WIFEXITED(status) ? WEXITSTATUS(status) : -1};
}

// Single-quoted for the shell.
std::string quoted(const std::string& text) {
  std::string q = "'";
  for (const char c : text) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

}  // namespace

config::CampaignFile prepare_campaign_dir(const fs::path& campaign_file, const fs::path& out) {
  const std::string text = read_text(campaign_file);
  const fs::path base = fs::absolute(campaign_file).parent_path().lexically_normal();
  (void)config::read_campaign(campaign_file);  // a malformed file fails here, naming itself, before out is touched
  fs::create_directories(out);
  const fs::path copy = out / "campaign.toml";
  std::error_code ec;
  if (fs::exists(copy, ec) && read_text(copy) != text)
    throw io::InputError(out.string(), "holds another campaign (campaign.toml differs from " + campaign_file.string() +
                                           "): use another --out, or remove the folder");
  io::write_file_atomically(copy, text);
  io::write_file_atomically(out / "campaign_base.txt", base.string() + "\n");
  return load_campaign_dir(out);
}

config::CampaignFile load_campaign_dir(const fs::path& out) {
  std::error_code ec;
  if (!fs::exists(out / "campaign.toml", ec))
    throw io::InputError(out.string(), "not a campaign folder (no campaign.toml): run `ultratrack campaign run` first");
  std::string base = read_text(out / "campaign_base.txt");
  while (!base.empty() && (base.back() == '\n' || base.back() == '\r')) base.pop_back();
  return config::read_campaign(out / "campaign.toml", base);
}

std::vector<int> pending_runs(const config::CampaignFile& campaign, const fs::path& out) {
  std::vector<int> pending;
  for (const pipelines::CampaignRun& run : pipelines::expand_campaign(campaign.axes))
    if (pipelines::campaign_run_status(pipelines::campaign_run_dir(out, run.index)).state !=
        pipelines::CampaignRunState::kComplete)
      pending.push_back(run.index);
  return pending;
}

bool run_campaign_index(const config::CampaignFile& campaign, const fs::path& out, int index, const fs::path& program,
                        std::stop_token stop) {
  const std::vector<pipelines::CampaignRun> runs = pipelines::expand_campaign(campaign.axes);
  if (index < 0 || index >= static_cast<int>(runs.size()))
    throw io::InputError("command line", fmt::format("run index {} is outside 0..{}", index, runs.size() - 1));
  const pipelines::CampaignRun& run = runs[static_cast<std::size_t>(index)];
  const fs::path dir = pipelines::campaign_run_dir(out, index);
  if (pipelines::campaign_run_status(dir).state == pipelines::CampaignRunState::kComplete) return true;
  if (!campaign.steps.empty())
    return run_campaign_steps(campaign, run, dir, program, stop).state == pipelines::CampaignRunState::kComplete;
  pipelines::CampaignJob job;
  try {
    job = config::campaign_job(campaign, run);
  } catch (const std::exception& e) {
    pipelines::record_campaign_run_failure(run, dir, e.what());
    return false;
  }
  return pipelines::run_campaign_job(job, dir, stop).state == pipelines::CampaignRunState::kComplete;
}

int run_campaign_local(const config::CampaignFile& campaign, const fs::path& out, int jobs, const fs::path& program,
                       std::FILE* log, std::stop_token stop) {
  const std::vector<int> pending = pending_runs(campaign, out);
  std::atomic<std::size_t> next{0};
  std::atomic<int> failed{0};
  std::mutex log_mutex;
  const auto worker = [&] {
    for (std::size_t i = next++; i < pending.size() && !stop.stop_requested(); i = next++) {
      const auto start = std::chrono::steady_clock::now();
      const bool ok = run_campaign_index(campaign, out, pending[i], program, stop);
      if (!ok && !stop.stop_requested()) ++failed;
      if (!log) continue;
      const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      const pipelines::CampaignRunStatus status =
          pipelines::campaign_run_status(pipelines::campaign_run_dir(out, pending[i]));
      std::lock_guard lock(log_mutex);
      fmt::print(log, "campaign: run {} {} ({:.1f} s){}\n", pipelines::campaign_run_folder(pending[i]),
                 ok                                                     ? "complete"
                 : status.state == pipelines::CampaignRunState::kFailed ? "FAILED"
                                                                        : "stopped",
                 wall_s, status.message.empty() ? "" : ": " + status.message);
      std::fflush(log);
    }
  };
  const int threads = std::max(1, std::min<int>(jobs, static_cast<int>(pending.size())));
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(worker);
  worker();
  for (std::thread& t : pool) t.join();
  return failed;
}

std::string slurm_script(const config::CampaignFile& campaign, const fs::path& out, std::size_t pending,
                         const fs::path& program) {
  const config::SlurmResources& s = campaign.slurm;
  const std::size_t tasks =
      (pending + static_cast<std::size_t>(s.runs_per_task) - 1) / static_cast<std::size_t>(s.runs_per_task);
  const fs::path dir = fs::absolute(out).lexically_normal();
  std::string text = "#!/bin/bash\n";
  text += fmt::format("#SBATCH --job-name=ultratrack-{}\n", campaign.name.empty() ? "campaign" : campaign.name);
  text +=
      fmt::format("#SBATCH --array=0-{}{}\n", tasks - 1, s.max_parallel > 0 ? fmt::format("%{}", s.max_parallel) : "");
  text +=
      fmt::format("#SBATCH --time={}\n#SBATCH --cpus-per-task={}\n#SBATCH --mem={}\n", s.time, s.cpus_per_task, s.mem);
  if (!s.partition.empty()) text += fmt::format("#SBATCH --partition={}\n", s.partition);
  if (!s.account.empty()) text += fmt::format("#SBATCH --account={}\n", s.account);
  text += fmt::format("#SBATCH --output={}/slurm/task_%a.log\n", dir.string());
  for (const std::string& e : s.extra) text += "#SBATCH " + e + "\n";
  text += fmt::format(
      "# Task k runs lines k*{0}+1 .. k*{0}+{0} of pending.txt (the runs not complete at submission); a run already\n"
      "# complete is skipped by run-one, so a resubmitted task redoes only what is missing.\n"
      "set -u\n"
      "first=$((SLURM_ARRAY_TASK_ID * {0} + 1))\n"
      "status=0\n"
      "for index in $(sed -n \"${{first}},$((first + {0} - 1))p\" {1}); do\n"
      "  {2} campaign run-one {3} \"$index\" || status=1\n"
      "done\n"
      "exit $status\n",
      s.runs_per_task, quoted((dir / "slurm" / "pending.txt").string()), quoted(program.string()),
      quoted(dir.string()));
  return text;
}

SlurmSubmission run_campaign_slurm(const config::CampaignFile& campaign, const fs::path& out, const fs::path& program,
                                   bool no_wait, double poll_s, std::FILE* log) {
  SlurmSubmission submission;
  const std::vector<int> pending = pending_runs(campaign, out);
  submission.runs = pending.size();
  if (pending.empty()) return submission;
  const std::size_t per = static_cast<std::size_t>(campaign.slurm.runs_per_task);
  submission.tasks = (pending.size() + per - 1) / per;
  fs::create_directories(out / "slurm");
  std::string list;
  for (const int i : pending) list += std::to_string(i) + "\n";
  io::write_file_atomically(out / "slurm" / "pending.txt", list);
  const fs::path script = out / "slurm" / "campaign.sbatch";
  io::write_file_atomically(script, slurm_script(campaign, out, pending.size(), program));
  const auto [answer, status] = capture("sbatch --parsable " + quoted(script.string()));
  std::string id = answer.substr(0, answer.find_first_of(";\n"));
  if (status != 0 || id.empty() || id.find_first_not_of("0123456789_") != std::string::npos)
    throw std::runtime_error(fmt::format("sbatch failed (exit status {}): {}", status, answer));
  submission.job_id = id;
  if (log)
    fmt::print(log, "campaign: submitted Slurm job {}: {} runs in {} array tasks\n", id, pending.size(),
               submission.tasks);
  if (no_wait) return submission;
  for (;;) {
    const auto [queue, queue_status] = capture("squeue -h -j " + id + " 2>/dev/null");
    if (queue_status != 0 || queue.find_first_not_of(" \n") == std::string::npos) break;
    std::this_thread::sleep_for(std::chrono::duration<double>(poll_s));
  }
  if (log) fmt::print(log, "campaign: Slurm job {} has left the queue\n", id);
  return submission;
}

}  // namespace ultratrack::tools
